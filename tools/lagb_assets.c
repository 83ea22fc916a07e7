// tactus-lagb-assets: the LAGB organs from a labelled volume to surfaces and
// tetrahedra (docs/lagb.md, assets/lagb/README.md).
//
//   tactus-lagb-assets all OUTDIR [volume=FILE] [voxel=MM] [label.ORGAN=V[+V...]]
//                                 [faces.ORGAN=N] [tets.ORGAN=N]
//   tactus-lagb-assets phantom OUT.json|OUT.nii[.gz] [voxel=MM]
//   tactus-lagb-assets tets SURFACE.obj PREFIX [tets=N]
//   tactus-lagb-assets check DIR
//
// all: the volume (the procedural phantom, or FILE: NIfTI or raw + JSON
// header), each organ's surface by GTS marching cubes and decimation
// (ORGAN.obj), tetrahedra by tetgen for the soft organs (ORGAN.node/.ele/
// .face), and lagb.json naming them. check: every surface closed, manifold,
// consistently oriented, no tetrahedron inverted, the worst dihedral angles.
// Bad input: one line naming the file on stderr, exit status 2, nothing
// written. A check that finds a defect: exit status 1.
#include "tools/lagb/mesh.h"
#include "tools/lagb/surface.h"
#include "tools/lagb/tetra.h"
#include "tools/lagb/volume.h"

#include "model/error.h"

#include <dirent.h>
#include <errno.h>
#include <jansson.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#ifdef TX_HAVE_ASSIMP
#include <assimp/cimport.h>
#include <assimp/scene.h>
#endif

#ifndef TX_TETGEN
#define TX_TETGEN ""
#endif

static const char* prog = "tactus-lagb-assets";

static int bad(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
static int bad(const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  fprintf(stderr, "%s: ", prog);
  vfprintf(stderr, fmt, ap);
  fprintf(stderr, "\n");
  va_end(ap);
  return 2;
}

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

static const char* tetgen_path(void) {
  const char* e = getenv("TACTUS_TETGEN");
  return e && *e ? e : TX_TETGEN;
}

// the organs of the scene, in the paper's counts (a closed surface has an
// even number of triangles: the stomach's 1863 becomes 1862, see the README)
enum { LIVER, STOMACH, SPLEEN, PERITONEUM, ORGANS };
typedef struct organ {
  const char* name;
  int labels[TX_LAGB_MAX_LABELS];
  int nlabels;
  int faces;  // 0: left out
  int tets;   // 0: a surface only
} organ;

static void default_organs(organ o[ORGANS]) {
  o[LIVER] = (organ){"liver", {TX_LAGB_LIVER}, 1, 2484, 3000};
  o[STOMACH] = (organ){"stomach", {TX_LAGB_STOMACH}, 1, 1862, 3000};
  o[SPLEEN] = (organ){"spleen", {TX_LAGB_SPLEEN}, 1, 1040, 0};
  o[PERITONEUM] = (organ){"peritoneum", {TX_LAGB_CAVITY}, 1, 384, 0};
}

static int organ_index(const char* name, size_t len) {
  const char* names[ORGANS] = {"liver", "stomach", "spleen", "peritoneum"};
  for (int i = 0; i < ORGANS; i++)
    if (strlen(names[i]) == len && strncmp(names[i], name, len) == 0) return i;
  return -1;
}

// a whole number from lo to hi, or -1
static long whole(const char* s, long lo, long hi) {
  char* end;
  errno = 0;
  long v = strtol(s, &end, 10);
  return end == s || *end || errno || v < lo || v > hi ? -1 : v;
}

static bool ends_with(const char* s, const char* tail) {
  size_t a = strlen(s), b = strlen(tail);
  return a >= b && strcmp(s + a - b, tail) == 0;
}

// reads a volume by its extension; labels from a JSON header go into o
static bool read_volume(const char* path, tx_lagb_volume* v, organ o[ORGANS], bool set[ORGANS]) {
  if (ends_with(path, ".json")) {
    tx_lagb_label lab[32];
    int n = 0;
    if (!tx_lagb_volume_read_json(path, v, lab, 32, &n)) return false;
    for (int i = 0; i < n; i++) {
      int k = organ_index(lab[i].name, strlen(lab[i].name));
      if (k >= 0 && !set[k]) o[k].labels[0] = lab[i].value, o[k].nlabels = 1;
    }
    return true;
  }
  if (ends_with(path, ".nii") || ends_with(path, ".nii.gz")) return tx_lagb_volume_read_nifti(path, v);
  tx_set_error("%s: a volume is a .json header (raw voxels) or NIfTI (.nii, .nii.gz)", path);
  return false;
}

// ---- a staging folder: every output goes there first and is moved into
// OUTDIR only when the whole run succeeded

typedef struct stage {
  char dir[4096];
  char out[4096];
  char names[32][64];
  int n;
} stage;

static bool stage_open(stage* s, const char* out) {
  s->n = 0;
  snprintf(s->out, sizeof s->out, "%s", out);
  struct stat stt;
  if (stat(out, &stt) != 0 || !S_ISDIR(stt.st_mode)) {
    tx_set_error("%s: not a folder", out);
    return false;
  }
  if (snprintf(s->dir, sizeof s->dir, "%s/.lagb-assets.XXXXXX", out) >= (int)sizeof s->dir || !mkdtemp(s->dir)) {
    tx_set_error("%s: cannot write here: %s", out, strerror(errno));
    return false;
  }
  return true;
}

static const char* stage_path(stage* s, const char* name) {
  static char p[4200];
  if (s->n < 32) snprintf(s->names[s->n++], sizeof s->names[0], "%s", name);
  snprintf(p, sizeof p, "%s/%s", s->dir, name);
  return p;
}

static void stage_close(stage* s, bool commit) {
  char from[4200], to[4200];
  for (int i = 0; i < s->n; i++) {
    snprintf(from, sizeof from, "%s/%s", s->dir, s->names[i]);
    snprintf(to, sizeof to, "%s/%s", s->out, s->names[i]);
    if (commit) rename(from, to);
    else remove(from);
  }
  // anything else left there (a tetgen working folder of a failed run)
  DIR* d = opendir(s->dir);
  if (d) {
    struct dirent* e;
    while ((e = readdir(d)))
      if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) {
        if (snprintf(from, sizeof from, "%s/%s", s->dir, e->d_name) < (int)sizeof from) remove(from);
      }
    closedir(d);
  }
  rmdir(s->dir);
}

// ---- all

static int cmd_all(int argc, char** argv) {
  if (argc < 1 || argv[0][0] == '-') return bad("all: expected OUTDIR first (--help for the keys)");
  const char* outdir = argv[0];
  organ o[ORGANS];
  default_organs(o);
  bool label_set[ORGANS] = {false};
  const char* volume = NULL;
  tx_lagb_phantom_def pd = tx_lagb_phantom_def_default();
  for (int i = 1; i < argc; i++) {
    const char* a = argv[i];
    const char* eq = strchr(a, '=');
    if (!eq) return bad("%s: expected KEY=VALUE", a);
    const char* val = eq + 1;
    const char* dot = memchr(a, '.', (size_t)(eq - a));
    if (strncmp(a, "volume=", 7) == 0) {
      volume = val;
    } else if (strncmp(a, "voxel=", 6) == 0) {
      char* end;
      double mm = strtod(val, &end);
      if (end == val || *end || !(mm >= 0.2 && mm <= 20)) return bad("%s: voxel must be 0.2 to 20 (mm)", a);
      pd.voxel = mm * 1e-3;
    } else if (dot) {
      int k = organ_index(dot + 1, (size_t)(eq - dot - 1));
      if (k < 0) return bad("%s: unknown organ (liver, stomach, spleen, peritoneum)", a);
      size_t klen = (size_t)(dot - a);
      if (klen == 5 && strncmp(a, "label", 5) == 0) {
        o[k].nlabels = 0;
        char buf[256];
        snprintf(buf, sizeof buf, "%s", val);
        for (char* t = strtok(buf, "+"); t; t = strtok(NULL, "+")) {
          long l = whole(t, 1, 65535);
          if (l < 0 || o[k].nlabels == TX_LAGB_MAX_LABELS)
            return bad("%s: expected labels V[+V...], whole numbers from 1 to 65535, at most %d", a,
                       TX_LAGB_MAX_LABELS);
          o[k].labels[o[k].nlabels++] = (int)l;
        }
        if (o[k].nlabels == 0) return bad("%s: expected labels V[+V...]", a);
        label_set[k] = true;
      } else if (klen == 5 && strncmp(a, "faces", 5) == 0) {
        long f = whole(val, 0, 1000000);
        if (f < 0 || (f > 0 && (f < 4 || f % 2)))
          return bad("%s: faces must be 0 (leave the organ out) or an even number from 4", a);
        o[k].faces = (int)f;
      } else if (klen == 4 && strncmp(a, "tets", 4) == 0) {
        long t = whole(val, 0, 1000000);
        if (t < 0 || (t > 0 && t < 4)) return bad("%s: tets must be 0 (a surface only) or at least 4", a);
        o[k].tets = (int)t;
      } else {
        return bad("%s: unknown key (--help lists them)", a);
      }
    } else {
      return bad("%s: unknown key (--help lists them)", a);
    }
  }
  double t0 = now();
  tx_lagb_volume v;
  const char* source = volume ? volume : "phantom";
  if (volume) {
    if (!read_volume(volume, &v, o, label_set)) return bad("%s", tx_error());
  } else if (!tx_lagb_phantom(&pd, &v)) {
    return bad("voxel: %s", tx_error());
  }
  double t_volume = now() - t0;
  // the peritoneum bounds its own label and every organ inside it
  for (int k = 0; k < PERITONEUM; k++)
    for (int j = 0; j < o[k].nlabels && o[PERITONEUM].nlabels < TX_LAGB_MAX_LABELS; j++)
      if (o[k].faces > 0) o[PERITONEUM].labels[o[PERITONEUM].nlabels++] = o[k].labels[j];
  stage st;
  if (!stage_open(&st, outdir)) {
    tx_lagb_volume_free(&v);
    return bad("%s", tx_error());
  }
  printf("volume: %s, %d x %d x %d voxels of %.2f x %.2f x %.2f mm (%.2f s)\n", source, v.n[0], v.n[1], v.n[2],
         v.spacing[0] * 1e3, v.spacing[1] * 1e3, v.spacing[2] * 1e3, t_volume);
  json_t* manifest = json_object();
  json_t* organs = json_object();
  json_object_set_new(manifest, "generator", json_string("tactus-lagb-assets (tools/lagb_assets.c)"));
  json_object_set_new(manifest, "source", json_string(volume ? source : "procedural phantom (tools/lagb/volume.c)"));
  json_object_set_new(manifest, "voxel_m", json_pack("[fff]", v.spacing[0], v.spacing[1], v.spacing[2]));
  json_object_set_new(manifest, "frame", json_string("x patient's right, y anterior (up, supine), z cranial; metres"));
  json_object_set_new(manifest, "organs", organs);
  int rc = 0;
  for (int k = 0; k < ORGANS && rc == 0; k++) {
    if (o[k].faces == 0) continue;
    tx_lagb_surface_def sd = {.nlabels = o[k].nlabels, .faces = o[k].faces};
    memcpy(sd.labels, o[k].labels, sizeof sd.labels);
    tx_trimesh m;
    tx_lagb_surface_stats ss;
    if (!tx_lagb_surface(&v, &sd, &m, &ss)) {
      rc = bad("%s: %s: %s", source, o[k].name, tx_error());
      break;
    }
    tx_trimesh_report r;
    if (!tx_trimesh_inspect(&m, &r) || !tx_trimesh_report_ok(&r)) {
      tx_trimesh_free(&m);
      rc = bad("%s: %s: the surface is not closed, manifold and oriented: %d boundary edges, %d non-manifold edges, "
               "%d misoriented edges, %d non-manifold vertices, %d degenerate triangles",
               source, o[k].name, r.boundary_edges, r.nonmanifold_edges, r.misoriented_edges, r.nonmanifold_verts,
               r.degenerate);
      break;
    }
    char name[64], comment[256];
    snprintf(name, sizeof name, "%s.obj", o[k].name);
    snprintf(comment, sizeof comment, "%s from %s by tactus-lagb-assets: GTS marching cubes, decimated to %d",
             o[k].name, volume ? "a labelled volume" : "the procedural phantom", o[k].faces);
    if (!tx_trimesh_write_obj(&m, stage_path(&st, name), comment)) {
      tx_trimesh_free(&m);
      rc = bad("%s", tx_error());
      break;
    }
    printf("%-10s %8lld voxels, marching cubes (blocks of %d^3) %7d triangles -> %5d (%d vertices), %.3g l, %d "
           "pieces left out (%.2f s)\n",
           o[k].name, (long long)ss.voxels, ss.block, ss.mc_faces, m.nt, m.nv, r.volume * 1e3, ss.dropped, ss.seconds);
    json_t* jo = json_object();
    json_object_set_new(jo, "surface", json_string(name));
    json_object_set_new(jo, "triangles", json_integer(m.nt));
    json_object_set_new(jo, "vertices", json_integer(m.nv));
    json_t* jl = json_array();
    for (int j = 0; j < o[k].nlabels; j++) json_array_append_new(jl, json_integer(o[k].labels[j]));
    json_object_set_new(jo, "labels", jl);
    if (o[k].tets > 0) {
      char prefix[4200];
      snprintf(prefix, sizeof prefix, "%s/%s", st.dir, o[k].name);
      tx_lagb_tet_stats ts;
      if (!tx_lagb_tets(&m, o[k].tets, prefix, tetgen_path(), &ts)) {
        tx_trimesh_free(&m);
        json_decref(jo);
        rc = bad("%s: %s: %s", source, o[k].name, tx_error());
        break;
      }
      const char* ext[] = {"node", "ele", "face"};
      for (int e = 0; e < 3; e++) {
        snprintf(name, sizeof name, "%s.%s", o[k].name, ext[e]);
        stage_path(&st, name);
      }
      printf("%-10s tetgen %s: %d tetrahedra filling the surface coarsened to %d triangles, %d runs (%.2f s)\n",
             o[k].name, ts.switches, ts.tets, ts.hull_faces, ts.runs, ts.seconds);
      snprintf(name, sizeof name, "%s.node", o[k].name);
      json_object_set_new(jo, "nodes", json_string(name));
      snprintf(name, sizeof name, "%s.ele", o[k].name);
      json_object_set_new(jo, "elements", json_string(name));
      json_object_set_new(jo, "tetrahedra", json_integer(ts.tets));
      json_object_set_new(jo, "tetgen", json_string(ts.switches));
      json_object_set_new(jo, "hull_triangles", json_integer(ts.hull_faces));
    }
    json_object_set_new(organs, o[k].name, jo);
    tx_trimesh_free(&m);
  }
  tx_lagb_volume_free(&v);
  if (rc == 0) {
    char part[4200];
    snprintf(part, sizeof part, "%s", stage_path(&st, "lagb.json"));
    if (json_dump_file(manifest, part, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(9)) != 0)
      rc = bad("%s/lagb.json: write failed", outdir);
  }
  json_decref(manifest);
  stage_close(&st, rc == 0);
  if (rc == 0) printf("wrote %s: volume to tetrahedra in %.2f s\n", outdir, now() - t0);
  return rc;
}

// ---- phantom

static int cmd_phantom(int argc, char** argv) {
  if (argc < 1 || argv[0][0] == '-') return bad("phantom: expected OUT.json or OUT.nii[.gz] first");
  const char* out = argv[0];
  tx_lagb_phantom_def pd = tx_lagb_phantom_def_default();
  for (int i = 1; i < argc; i++) {
    char* end;
    if (strncmp(argv[i], "voxel=", 6) != 0) return bad("%s: unknown key (voxel=MM)", argv[i]);
    double mm = strtod(argv[i] + 6, &end);
    if (end == argv[i] + 6 || *end || !(mm >= 0.2 && mm <= 20)) return bad("%s: voxel must be 0.2 to 20 (mm)", argv[i]);
    pd.voxel = mm * 1e-3;
  }
  bool nifti = ends_with(out, ".nii") || ends_with(out, ".nii.gz");
  if (!nifti && !ends_with(out, ".json")) return bad("%s: write a .json header (raw voxels) or NIfTI (.nii, .nii.gz)", out);
  tx_lagb_volume v;
  if (!tx_lagb_phantom(&pd, &v)) return bad("voxel: %s", tx_error());
  tx_lagb_label lab[] = {{"liver", TX_LAGB_LIVER}, {"stomach", TX_LAGB_STOMACH}, {"spleen", TX_LAGB_SPLEEN},
                         {"peritoneum", TX_LAGB_CAVITY}};
  bool ok = nifti ? tx_lagb_volume_write_nifti(&v, out) : tx_lagb_volume_write_json(&v, out, lab, 4);
  int n[3] = {v.n[0], v.n[1], v.n[2]};
  tx_lagb_volume_free(&v);
  if (!ok) return bad("%s", tx_error());
  printf("wrote %s: %d x %d x %d voxels of %.2f mm\n", out, n[0], n[1], n[2], pd.voxel * 1e3);
  return 0;
}

// ---- tets

static int cmd_tets(int argc, char** argv) {
  if (argc < 2 || argv[0][0] == '-') return bad("tets: expected SURFACE.obj PREFIX");
  int target = 3000;
  for (int i = 2; i < argc; i++) {
    long t = strncmp(argv[i], "tets=", 5) == 0 ? whole(argv[i] + 5, 4, 1000000) : -1;
    if (t < 0) return bad("%s: expected tets=N, N at least 4", argv[i]);
    target = (int)t;
  }
  tx_trimesh m;
  if (!tx_trimesh_read_obj(argv[0], &m)) return bad("%s", tx_error());
  tx_trimesh_report r;
  if (!tx_trimesh_inspect(&m, &r)) {
    tx_trimesh_free(&m);
    return bad("%s: %s", argv[0], tx_error());
  }
  if (!tx_trimesh_report_ok(&r)) {
    tx_trimesh_free(&m);
    return bad("%s: not a closed, manifold, outward surface: %d boundary edges (holes), %d non-manifold edges, %d "
               "misoriented edges, %d non-manifold vertices, %d degenerate triangles, volume %.3g m^3",
               argv[0], r.boundary_edges, r.nonmanifold_edges, r.misoriented_edges, r.nonmanifold_verts, r.degenerate,
               r.volume);
  }
  // tetgen writes beside PREFIX first; the three files appear together
  tx_lagb_tet_stats ts;
  bool ok = tx_lagb_tets(&m, target, argv[1], tetgen_path(), &ts);
  tx_trimesh_free(&m);
  if (!ok) return bad("%s: %s", argv[0], tx_error());
  printf("wrote %s.node/.ele/.face: tetgen %s, %d tetrahedra filling the surface coarsened to %d triangles (%.2f s)\n",
         argv[1], ts.switches, ts.tets, ts.hull_faces, ts.seconds);
  return 0;
}

// ---- check

static int cmd_check(int argc, char** argv) {
  if (argc != 1 || argv[0][0] == '-') return bad("check: expected DIR (holding lagb.json)");
  char path[4200];
  snprintf(path, sizeof path, "%s/lagb.json", argv[0]);
  json_error_t je;
  json_t* root = json_load_file(path, 0, &je);
  if (!root) return bad("%s:%d:%d: %s", path, je.line, je.column, je.text);
  json_t* organs = json_object_get(root, "organs");
  if (!json_is_object(organs) || json_object_size(organs) == 0) {
    json_decref(root);
    return bad("%s: key \"organs\" must name at least one organ", path);
  }
  int defects = 0, rc = 0, held = 0;
  tx_trimesh kept[8];
  const char* kept_name[8];
  const char* name;
  json_t* jo;
  json_object_foreach(organs, name, jo) {
    const char* surf = json_string_value(json_object_get(jo, "surface"));
    if (!surf) {
      rc = bad("%s: organs.%s.surface is missing", path, name);
      break;
    }
    char sp[4200];
    snprintf(sp, sizeof sp, "%s/%s", argv[0], surf);
    tx_trimesh m;
    if (!tx_trimesh_read_obj(sp, &m)) {
      rc = bad("%s", tx_error());
      break;
    }
    tx_trimesh_report r;
    if (!tx_trimesh_inspect(&m, &r)) {
      tx_trimesh_free(&m);
      rc = bad("%s: %s", sp, tx_error());
      break;
    }
    bool ok = tx_trimesh_report_ok(&r) && r.components == 1;
    printf("%-10s surface %5d triangles %5d vertices: %s (boundary %d, non-manifold %d+%d, misoriented %d, "
           "degenerate %d, pieces %d, Euler %d, volume %.4g l, area %.4g m^2)\n",
           name, m.nt, m.nv, ok ? "closed, manifold, oriented outward" : "DEFECT", r.boundary_edges,
           r.nonmanifold_edges, r.nonmanifold_verts, r.misoriented_edges, r.degenerate, r.components, r.euler,
           r.volume * 1e3, r.area);
    defects += !ok;
#ifdef TX_HAVE_ASSIMP
    // the format is one assimp reads: the scene's triangles are the file's
    const struct aiScene* sc = aiImportFile(sp, 0);
    unsigned faces = 0;
    for (unsigned i = 0; sc && i < sc->mNumMeshes; i++) faces += sc->mMeshes[i]->mNumFaces;
    bool loads = sc && faces == (unsigned)m.nt;
    printf("%-10s assimp reads %u triangles: %s\n", name, faces, loads ? "ok" : "DEFECT");
    defects += !loads;
    if (sc) aiReleaseImport(sc);
#endif
    if (held < 8) kept_name[held] = name, kept[held++] = m;
    else tx_trimesh_free(&m);
    const char* node = json_string_value(json_object_get(jo, "nodes"));
    const char* ele = json_string_value(json_object_get(jo, "elements"));
    if (node && ele) {
      char np[4200], ep[4200];
      snprintf(np, sizeof np, "%s/%s", argv[0], node);
      snprintf(ep, sizeof ep, "%s/%s", argv[0], ele);
      tx_tetmesh t;
      if (!tx_tetmesh_read(np, ep, &t)) {
        rc = bad("%s", tx_error());
        break;
      }
      tx_tetmesh_report tr;
      tx_tetmesh_inspect(&t, &tr);
      bool tok = tr.inverted == 0 && tr.degenerate == 0 && fabs(tr.volume - r.volume) <= 1e-3 * r.volume;
      printf("%-10s tetrahedra %5d nodes %5d: %s (inverted %d, degenerate %d, volume %.4g l), dihedral angles "
             "%.2f to %.2f degrees\n",
             name, t.ne, t.nv, tok ? "none inverted, fills the surface" : "DEFECT", tr.inverted, tr.degenerate,
             tr.volume * 1e3, tr.min_dihedral, tr.max_dihedral);
      defects += !tok;
      tx_tetmesh_free(&t);
    }
  }
  // organs apart from each other, and inside the peritoneum: a body that
  // starts inside another is pushed out at the first step, violently
  for (int i = 0; rc == 0 && i < held; i++)
    for (int j = 0; j < held; j++) {
      if (i == j) continue;
      bool outer = strcmp(kept_name[j], "peritoneum") == 0;
      if (strcmp(kept_name[i], "peritoneum") == 0) continue;
      int wrong = 0;
      for (int k = 0; k < kept[i].nv; k++) {
        bool in = tx_trimesh_winding(&kept[j], kept[i].v + 3 * k) > 0.5;
        wrong += outer ? !in : in;
      }
      if (wrong || outer)
        printf("%-10s %s %s: %d of %d vertices %s\n", kept_name[i], outer ? "inside" : "apart from", kept_name[j], wrong,
               kept[i].nv, wrong ? (outer ? "outside: DEFECT" : "inside it: DEFECT") : "ok");
      defects += wrong > 0;
    }
  for (int i = 0; i < held; i++) tx_trimesh_free(&kept[i]);
  json_decref(root);
  if (rc) return rc;
  printf("%s: %s\n", argv[0], defects ? "DEFECTS found" : "every check passed");
  return defects ? 1 : 0;
}

int main(int argc, char** argv) {
  if (argc >= 2 && (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0)) {
    printf("usage:\n"
           "  %s all OUTDIR [volume=FILE] [voxel=MM] [label.ORGAN=V[+V...]] [faces.ORGAN=N] [tets.ORGAN=N]\n"
           "  %s phantom OUT.json|OUT.nii[.gz] [voxel=MM]\n"
           "  %s tets SURFACE.obj PREFIX [tets=N]\n"
           "  %s check DIR\n"
           "ORGAN: liver stomach spleen peritoneum. FILE: NIfTI (.nii, .nii.gz) or a .json header of raw voxels.\n"
           "tetgen: %s (TACTUS_TETGEN overrides). NIfTI: %s.\n",
           prog, prog, prog, prog, *tetgen_path() ? tetgen_path() : "not found", tx_lagb_have_nifti() ? "yes" : "no");
    return 0;
  }
  if (argc < 2) return bad("expected a command: all, phantom, tets or check (--help)");
  if (strcmp(argv[1], "all") == 0) return cmd_all(argc - 2, argv + 2);
  if (strcmp(argv[1], "phantom") == 0) return cmd_phantom(argc - 2, argv + 2);
  if (strcmp(argv[1], "tets") == 0) return cmd_tets(argc - 2, argv + 2);
  if (strcmp(argv[1], "check") == 0) return cmd_check(argc - 2, argv + 2);
  return bad("%s: unknown command (all, phantom, tets, check)", argv[1]);
}
