// tactus describe --instrument FILE.urdf: reads an instrument description as
// the instruments controller does (urdfdom, assimp) and prints what it holds.
#include "../scenarios/command.h"

#include <tactus/config.h>
#include <tactus/tactus.h>

#include <stdio.h>

#if TX_WITH_URDFDOM && TX_WITH_ASSIMP
#include "../controllers/instruments/instrument_desc.h"

static const char* shape_name[] = {"box", "cylinder", "sphere"};

int tx_cmd_describe_instrument(const char* path) {
  tx_instrument_desc* d = tx_instrument_desc_load(path);
  if (!d) return tx_bad_input("%s", tx_error());
  const tx_urdf* u = d->urdf;
  printf("%s: %s\n%d links, %d jaw joints, %.1f g\n\nlinks (mass, centre of mass in the link frame, the inertia's diagonal "
         "about it):\n",
         u->name, path, u->nlinks, tx_instrument_desc_jaws(d), 1000 * tx_instrument_desc_mass(d));
  for (int i = 0; i < u->nlinks; i++) {
    const tx_urdf_link* l = &u->links[i];
    printf("  %-12s %8.2f g  com (%g, %g, %g) m  I (%.3g, %.3g, %.3g) kg m^2\n", l->name, 1000 * l->mass, l->com.p[0],
           l->com.p[1], l->com.p[2], l->inertia[0], l->inertia[3], l->inertia[5]);
    for (int k = 0; k < l->nshapes; k++) {
      const tx_urdf_shape* s = &l->shapes[k];
      printf("    collision %-10s %-8s size (%g, %g, %g) at (%g, %g, %g)\n", s->name, shape_name[s->kind], s->size[0],
             s->size[1], s->size[2], s->pose.p[0], s->pose.p[1], s->pose.p[2]);
    }
    if (l->mesh[0])
      printf("    mesh %s: %d vertices, %d triangles, volume %.4g cm^3\n", l->mesh, d->meshes[i].nvertices,
             d->meshes[i].ntriangles, 1e6 * tx_mesh_volume(&d->meshes[i]));
  }
  printf("\njoints (0 rad = jaws closed):\n");
  for (int j = 0; j < u->njoints; j++) {
    const tx_urdf_joint* jt = &u->joints[j];
    if (jt->fixed) printf("  %-16s fixed     %s -> %s\n", jt->name, u->links[jt->parent].name, u->links[jt->child].name);
    else
      printf("  %-16s revolute  %s -> %s  axis (%g, %g, %g)  %g to %g rad  %g N m  %g rad/s\n", jt->name,
             u->links[jt->parent].name, u->links[jt->child].name, jt->axis[0], jt->axis[1], jt->axis[2], jt->lower,
             jt->upper, jt->effort, jt->velocity);
  }
  tx_instrument_desc_free(d);
  return 0;
}
#else
int tx_cmd_describe_instrument(const char* path) {
  (void)path;
  return tx_bad_input("describe --instrument: built without urdfdom or assimp (TX_WITH_URDFDOM, TX_WITH_ASSIMP)");
}
#endif
