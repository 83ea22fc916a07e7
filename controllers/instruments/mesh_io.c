// tx_mesh_load over assimp's C interface.
#include "mesh_io.h"

#include "../../model/error.h"

#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

void tx_mesh_free(tx_mesh* m) {
  if (!m) return;
  free(m->vertices);
  free(m->triangles);
  *m = (tx_mesh){0};
}

bool tx_mesh_load(const char* path, tx_mesh* out) {
  *out = (tx_mesh){0};
  struct stat st;
  // assimp's own message for a missing file does not say which
  if (stat(path, &st) != 0) return tx_set_error("%s: %s", path, strerror(errno)), false;
  if (!S_ISREG(st.st_mode)) return tx_set_error("%s: not a file", path), false;
  const struct aiScene* sc =
      aiImportFile(path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_PreTransformVertices | aiProcess_SortByPType);
  if (!sc) {
    const char* why = aiGetErrorString();
    // assimp refuses a scene with no meshes as a whole; say what that means here
    if (why && (strstr(why, "no meshes") || strstr(why, "No output meshes"))) return tx_set_error("%s: no faces", path), false;
    return tx_set_error("%s: %s", path, why && *why ? why : "cannot be read"), false;
  }
  long nv = 0, nt = 0;
  for (unsigned i = 0; i < sc->mNumMeshes; i++) {
    const struct aiMesh* m = sc->mMeshes[i];
    if (!(m->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue; // points and lines have no faces
    nv += m->mNumVertices;
    for (unsigned f = 0; f < m->mNumFaces; f++) nt += m->mFaces[f].mNumIndices == 3;
  }
  if (nt == 0 || nv > 100000000 || nt > 100000000) {
    aiReleaseImport(sc);
    return tx_set_error("%s: %s", path, nt == 0 ? "no faces" : "too large"), false;
  }
  out->vertices = malloc(3 * (size_t)nv * sizeof *out->vertices);
  out->triangles = malloc(3 * (size_t)nt * sizeof *out->triangles);
  if (!out->vertices || !out->triangles) {
    aiReleaseImport(sc);
    tx_mesh_free(out);
    return tx_set_error("%s: out of memory", path), false;
  }
  for (unsigned i = 0; i < sc->mNumMeshes; i++) {
    const struct aiMesh* m = sc->mMeshes[i];
    if (!(m->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
    int base = out->nvertices;
    for (unsigned v = 0; v < m->mNumVertices; v++) {
      double* p = out->vertices + 3 * (size_t)out->nvertices++;
      p[0] = m->mVertices[v].x, p[1] = m->mVertices[v].y, p[2] = m->mVertices[v].z;
    }
    for (unsigned f = 0; f < m->mNumFaces; f++) {
      if (m->mFaces[f].mNumIndices != 3) continue;
      int* t = out->triangles + 3 * (size_t)out->ntriangles++;
      for (int k = 0; k < 3; k++) t[k] = base + (int)m->mFaces[f].mIndices[k];
    }
  }
  aiReleaseImport(sc);
  return true;
}

double tx_mesh_volume(const tx_mesh* m) {
  double v = 0;
  for (int i = 0; i < m->ntriangles; i++) {
    const double* a = m->vertices + 3 * m->triangles[3 * i];
    const double* b = m->vertices + 3 * m->triangles[3 * i + 1];
    const double* c = m->vertices + 3 * m->triangles[3 * i + 2];
    v += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  return v / 6;
}
