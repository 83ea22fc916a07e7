// The urdfdom adapter behind urdf.h: parse with urdf::parseURDFFile, check
// what an instrument needs, copy into C structs. urdfdom reports through
// console_bridge; its first error is caught here and becomes tx_error().
#include <console_bridge/console.h>
#include <tinyxml.h>
#include <urdf_parser/urdf_parser.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

extern "C" {
#include "urdf.h"
#include "../../model/error.h"
}

namespace {

// keeps urdfdom's first error (it may log several, and its own parse
// failure after the cause); prints nothing
class first_error : public console_bridge::OutputHandler {
 public:
  std::string text;
  void log(const std::string& t, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR && text.empty()) text = t;
  }
};

void copy_name(char* dst, const std::string& src) { std::snprintf(dst, TX_URDF_NAME_MAX, "%s", src.c_str()); }

tx_urdf_pose pose_of(const urdf::Pose& p) {
  tx_urdf_pose o;
  o.p[0] = p.position.x, o.p[1] = p.position.y, o.p[2] = p.position.z;
  o.q[0] = p.rotation.w, o.q[1] = p.rotation.x, o.q[2] = p.rotation.y, o.q[3] = p.rotation.z;
  return o;
}

bool fail(const char* path, const std::string& what) {
  tx_set_error("%s: %s", path, what.c_str());
  return false;
}

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

bool positive(double v) { return std::isfinite(v) && v > 0; }

bool read_link(const char* path, const std::string& dir, const urdf::Link& l, tx_urdf_link* out) {
  copy_name(out->name, l.name);
  std::string where = "link '" + l.name + "'";
  if (!l.inertial) return fail(path, where + ": no <inertial>");
  const urdf::Inertial& in = *l.inertial;
  if (!positive(in.mass)) return fail(path, where + " <mass>: must be positive, is " + num(in.mass));
  double I[6] = {in.ixx, in.ixy, in.ixz, in.iyy, in.iyz, in.izz};
  const char* names[6] = {"ixx", "ixy", "ixz", "iyy", "iyz", "izz"};
  for (int k = 0; k < 6; k++)
    if (!std::isfinite(I[k])) return fail(path, where + " <inertia> " + names[k] + ": not a number");
  for (int k : {0, 3, 5})
    if (!(I[k] > 0)) return fail(path, where + " <inertia> " + names[k] + ": must be positive, is " + num(I[k]));
  // positive definite (Sylvester) and a physical body (triangle inequality on the principal moments' diagonal)
  double m2 = I[0] * I[3] - I[1] * I[1];
  double det = I[0] * (I[3] * I[5] - I[4] * I[4]) - I[1] * (I[1] * I[5] - I[4] * I[2]) + I[2] * (I[1] * I[4] - I[3] * I[2]);
  if (!(m2 > 0 && det > 0)) return fail(path, where + " <inertia>: not positive definite");
  if (I[0] + I[3] < I[5] * (1 - 1e-9) || I[3] + I[5] < I[0] * (1 - 1e-9) || I[0] + I[5] < I[3] * (1 - 1e-9))
    return fail(path, where + " <inertia>: no body has these moments (each must be at most the sum of the other two)");
  out->mass = in.mass;
  out->com = pose_of(in.origin);
  for (int k = 0; k < 6; k++) out->inertia[k] = I[k];

  out->mesh[0] = 0;
  out->mesh_scale[0] = out->mesh_scale[1] = out->mesh_scale[2] = 1;
  for (const auto& v : l.visual_array) {
    if (!v || !v->geometry || v->geometry->type != urdf::Geometry::MESH) continue;
    const auto& mesh = static_cast<const urdf::Mesh&>(*v->geometry);
    if (out->mesh[0]) return fail(path, where + " <visual>: one mesh per link");
    if (mesh.filename.empty()) return fail(path, where + " <visual> <mesh>: no filename");
    if (mesh.filename.find("://") != std::string::npos)
      return fail(path, where + " <visual> <mesh> '" + mesh.filename + "': give a path relative to the URDF, not a URI");
    std::string full = mesh.filename[0] == '/' ? mesh.filename : dir + mesh.filename;
    if (full.size() >= TX_URDF_PATH_MAX) return fail(path, where + " <visual> <mesh>: path too long");
    std::snprintf(out->mesh, TX_URDF_PATH_MAX, "%s", full.c_str());
    out->mesh_pose = pose_of(v->origin);
    out->mesh_scale[0] = mesh.scale.x, out->mesh_scale[1] = mesh.scale.y, out->mesh_scale[2] = mesh.scale.z;
  }

  out->nshapes = 0;
  for (const auto& c : l.collision_array) {
    if (!c || !c->geometry) continue;
    std::string cw = where + " <collision" + (c->name.empty() ? "" : " name='" + c->name + "'") + ">";
    if (out->nshapes == TX_URDF_SHAPES_MAX)
      return fail(path, cw + ": more than " + std::to_string(TX_URDF_SHAPES_MAX) + " collision shapes");
    tx_urdf_shape* s = &out->shapes[out->nshapes];
    copy_name(s->name, c->name);
    s->pose = pose_of(c->origin);
    s->size[0] = s->size[1] = s->size[2] = 0;
    switch (c->geometry->type) {
      case urdf::Geometry::BOX: {
        const auto& b = static_cast<const urdf::Box&>(*c->geometry);
        s->kind = TX_URDF_BOX, s->size[0] = b.dim.x, s->size[1] = b.dim.y, s->size[2] = b.dim.z;
        break;
      }
      case urdf::Geometry::CYLINDER: {
        const auto& y = static_cast<const urdf::Cylinder&>(*c->geometry);
        s->kind = TX_URDF_CYLINDER, s->size[0] = y.radius, s->size[1] = y.length;
        break;
      }
      case urdf::Geometry::SPHERE:
        s->kind = TX_URDF_SPHERE, s->size[0] = static_cast<const urdf::Sphere&>(*c->geometry).radius;
        break;
      default:
        return fail(path, cw + ": collision shapes are primitives (box, cylinder, sphere)");
    }
    int n = s->kind == TX_URDF_BOX ? 3 : s->kind == TX_URDF_CYLINDER ? 2 : 1;
    for (int k = 0; k < n; k++)
      if (!positive(s->size[k])) return fail(path, cw + ": its size must be positive");
    out->nshapes++;
  }
  return true;
}

// urdfdom takes the first root it finds; number the links root first, then
// each joint's child after its parent
bool order_links(const urdf::ModelInterface& m, std::vector<std::string>& order) {
  order.push_back(m.getRoot()->name);
  for (size_t i = 0; i < order.size(); i++) {
    urdf::LinkConstSharedPtr l = m.getLink(order[i]);
    for (const auto& c : l->child_links) order.push_back(c->name);
  }
  return order.size() == m.links_.size();
}

}  // namespace

extern "C" tx_urdf* tx_urdf_load(const char* path) {
  std::ifstream f(path);
  if (!f) {
    tx_set_error("%s: %s", path, std::strerror(errno));
    return nullptr;
  }
  std::stringstream text;
  text << f.rdbuf();
  if (f.bad()) {
    tx_set_error("%s: cannot be read", path);
    return nullptr;
  }
  // urdfdom's reader says what is wrong with the XML but not where: read it
  // once with the same TinyXML for the line
  TiXmlDocument doc;
  doc.Parse(text.str().c_str());
  if (doc.Error()) {
    tx_set_error("%s: line %d: %s", path, doc.ErrorRow(), doc.ErrorDesc());
    return nullptr;
  }
  first_error catcher;
  console_bridge::useOutputHandler(&catcher);
  urdf::ModelInterfaceSharedPtr m;
  try {
    m = urdf::parseURDF(text.str());
  } catch (const std::exception& e) {
    catcher.text = e.what();
    m.reset();
  }
  console_bridge::restorePreviousOutputHandler();
  if (!m) {
    std::string why = catcher.text.empty() ? "not a URDF" : catcher.text;
    for (char& ch : why)
      if (ch == '\n' || ch == '\r') ch = ' ';
    tx_set_error("%s: %s", path, why.c_str());
    return nullptr;
  }
  std::vector<std::string> order;
  if (!m->getRoot() || !order_links(*m, order)) {
    tx_set_error("%s: the links are not one tree", path);
    return nullptr;
  }
  std::string p(path);
  size_t slash = p.rfind('/');
  std::string dir = slash == std::string::npos ? "" : p.substr(0, slash + 1);

  tx_urdf* u = static_cast<tx_urdf*>(std::calloc(1, sizeof *u));
  if (u) {
    u->links = static_cast<tx_urdf_link*>(std::calloc(order.size(), sizeof *u->links));
    u->joints = static_cast<tx_urdf_joint*>(std::calloc(order.size(), sizeof *u->joints));
  }
  if (!u || !u->links || !u->joints) {
    tx_urdf_free(u);
    tx_set_error("%s: out of memory", path);
    return nullptr;
  }
  copy_name(u->name, m->getName());
  for (const std::string& name : order) {
    if (!read_link(path, dir, *m->getLink(name), &u->links[u->nlinks])) {
      tx_urdf_free(u);
      return nullptr;
    }
    u->nlinks++;
  }
  for (size_t i = 1; i < order.size(); i++) { // every link but the root has its parent joint
    urdf::LinkConstSharedPtr l = m->getLink(order[i]);
    const urdf::Joint& j = *l->parent_joint;
    std::string where = "joint '" + j.name + "'";
    tx_urdf_joint* o = &u->joints[u->njoints];
    copy_name(o->name, j.name);
    o->parent = tx_urdf_link_index(u, j.parent_link_name.c_str());
    o->child = tx_urdf_link_index(u, j.child_link_name.c_str());
    o->origin = pose_of(j.parent_to_joint_origin_transform);
    o->fixed = j.type == urdf::Joint::FIXED;
    if (!o->fixed && j.type != urdf::Joint::REVOLUTE) {
      fail(path, where + ": type must be revolute or fixed");
      tx_urdf_free(u);
      return nullptr;
    }
    if (!o->fixed) {
      double n = std::sqrt(j.axis.x * j.axis.x + j.axis.y * j.axis.y + j.axis.z * j.axis.z);
      const urdf::JointLimits* lim = j.limits.get();
      const char* why = nullptr;
      if (!(n > 0)) why = " <axis>: zero";
      else if (!lim) why = ": no <limit>";
      else if (!(lim->lower <= lim->upper)) why = " <limit>: lower is above upper";
      else if (!positive(lim->effort) || !positive(lim->velocity)) why = " <limit>: effort and velocity must be positive";
      if (why) {
        fail(path, where + why);
        tx_urdf_free(u);
        return nullptr;
      }
      o->axis[0] = j.axis.x / n, o->axis[1] = j.axis.y / n, o->axis[2] = j.axis.z / n;
      o->lower = lim->lower, o->upper = lim->upper, o->effort = lim->effort, o->velocity = lim->velocity;
    }
    u->njoints++;
  }
  return u;
}

extern "C" void tx_urdf_free(tx_urdf* u) {
  if (!u) return;
  std::free(u->links);
  std::free(u->joints);
  std::free(u);
}

extern "C" int tx_urdf_link_index(const tx_urdf* u, const char* name) {
  for (int i = 0; i < u->nlinks; i++)
    if (std::strcmp(u->links[i].name, name) == 0) return i;
  return -1;
}
