// The labelled volume: the phantom, raw + JSON, NIfTI (see volume.h).
#include "tools/lagb/volume.h"

#include "model/error.h"

#include <errno.h>
#include <jansson.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef TX_HAVE_NIFTI
#include <nifti2_io.h>
#endif

tx_lagb_phantom_def tx_lagb_phantom_def_default(void) {
  return (tx_lagb_phantom_def){
      .voxel = 1.4e-3,
      .half = {0.19, 0.125, 0.18},
      .cavity_c = {0.0, 0.005, 0.0},
      .cavity_r = {0.175, 0.115, 0.165},
      .cavity_p = 3.0,
      .liver_right_c = {0.06, -0.01, 0.07},
      .liver_right_r = {0.08, 0.065, 0.07},
      .liver_left_c = {-0.04, 0.045, 0.085},
      .liver_left_r = {0.065, 0.025, 0.045},
      .stomach_scale = 1.0,
      .spleen_c = {-0.122, -0.035, 0.055},
      .spleen_r = {0.06, 0.035, 0.017},
  };
}

void tx_lagb_volume_free(tx_lagb_volume* v) {
  free(v->label);
  *v = (tx_lagb_volume){0};
}

int64_t tx_lagb_volume_count(const tx_lagb_volume* v) { return (int64_t)v->n[0] * v->n[1] * v->n[2]; }

static bool alloc_volume(tx_lagb_volume* v, const int n[3]) {
  for (int k = 0; k < 3; k++)
    if (n[k] < 1 || n[k] > 4096) {
      tx_set_error("volume size %d x %d x %d: each side must be 1 to 4096 voxels", n[0], n[1], n[2]);
      return false;
    }
  memcpy(v->n, n, sizeof v->n);
  v->label = calloc((size_t)tx_lagb_volume_count(v), sizeof(uint16_t));
  if (!v->label) {
    tx_set_error("volume of %d x %d x %d voxels: out of memory", n[0], n[1], n[2]);
    return false;
  }
  return true;
}

// the stomach's centreline from the oesophagus to the duodenum, RAS, m, and
// its radius; the fundus is a sphere on the greater curvature beside the cardia
static const double stomach_path[][4] = {
    {-0.015, -0.050, 0.135, 0.010},  // oesophagus, where the phantom cuts it
    {-0.022, -0.045, 0.100, 0.011},  // abdominal oesophagus
    {-0.032, -0.040, 0.075, 0.018},  // cardia
    {-0.058, -0.025, 0.045, 0.038},  // body, upper
    {-0.058, -0.008, 0.005, 0.038},  // body
    {-0.040, 0.004, -0.040, 0.033},  // body, lower
    {-0.005, 0.010, -0.062, 0.026},  // antrum
    {0.030, 0.006, -0.050, 0.019},   // antrum, pyloric canal
    {0.048, -0.002, -0.034, 0.011},  // pylorus
    {0.058, -0.012, -0.020, 0.010},  // duodenum, where the phantom cuts it
};
static const double fundus[4] = {-0.062, -0.038, 0.082, 0.035};
enum { STOMACH_KNOTS = sizeof stomach_path / sizeof stomach_path[0], STOMACH_SAMPLES = 24 };

// Catmull-Rom through the knots: point and radius at segment s, fraction u
static void stomach_at(int s, double u, double out[4]) {
  const double* p0 = stomach_path[s > 0 ? s - 1 : 0];
  const double* p1 = stomach_path[s];
  const double* p2 = stomach_path[s + 1];
  const double* p3 = stomach_path[s + 2 < STOMACH_KNOTS ? s + 2 : STOMACH_KNOTS - 1];
  double u2 = u * u, u3 = u2 * u;
  for (int k = 0; k < 4; k++)
    out[k] = 0.5 * (2 * p1[k] + (-p0[k] + p2[k]) * u + (2 * p0[k] - 5 * p1[k] + 4 * p2[k] - p3[k]) * u2 +
                    (-p0[k] + 3 * p1[k] - 3 * p2[k] + p3[k]) * u3);
}

static double ellipsoid(const double p[3], const double c[3], const double r[3]) {
  double s = 0;
  for (int k = 0; k < 3; k++) s += (p[k] - c[k]) * (p[k] - c[k]) / (r[k] * r[k]);
  return s;
}

bool tx_lagb_phantom(const tx_lagb_phantom_def* d, tx_lagb_volume* v) {
  *v = (tx_lagb_volume){0};
  if (!(d->voxel >= 0.2e-3 && d->voxel <= 20e-3)) {
    tx_set_error("voxel = %g m: must be 0.2 to 20 mm", d->voxel);
    return false;
  }
  int n[3];
  for (int k = 0; k < 3; k++) {
    n[k] = (int)ceil(2 * d->half[k] / d->voxel);
    v->spacing[k] = d->voxel;
    v->origin[k] = -0.5 * (n[k] - 1) * d->voxel;
  }
  if (!alloc_volume(v, n)) return false;
  // the stomach as a swept sphere: dense samples of the centreline
  enum { NS = (STOMACH_KNOTS - 1) * STOMACH_SAMPLES + 2 };
  double sweep[NS][4];
  int ns = 0;
  for (int s = 0; s + 1 < STOMACH_KNOTS; s++)
    for (int i = 0; i < STOMACH_SAMPLES; i++) stomach_at(s, (double)i / STOMACH_SAMPLES, sweep[ns++]);
  memcpy(sweep[ns++], stomach_path[STOMACH_KNOTS - 1], sizeof sweep[0]);
  memcpy(sweep[ns++], fundus, sizeof sweep[0]);
  for (int i = 0; i < ns; i++) sweep[i][3] *= d->stomach_scale;
  // the spleen's long axis runs along the lower left ribs, from posterior and
  // cranial to anterior and caudal; its thin axis faces the stomach
  const double su[3] = {0.0, 0.55, -0.835}, st[3] = {0.94, 0.0, 0.0};
  double sb[3] = {su[1] * st[2] - su[2] * st[1], su[2] * st[0] - su[0] * st[2], su[0] * st[1] - su[1] * st[0]};
  for (int z = 0; z < n[2]; z++)
    for (int y = 0; y < n[1]; y++)
      for (int x = 0; x < n[0]; x++) {
        double p[3] = {v->origin[0] + x * d->voxel, v->origin[1] + y * d->voxel, v->origin[2] + z * d->voxel};
        double c = 0;
        for (int k = 0; k < 3; k++) c += pow(fabs(p[k] - d->cavity_c[k]) / d->cavity_r[k], d->cavity_p);
        if (c > 1) continue;
        uint16_t l = TX_LAGB_CAVITY;
        if (ellipsoid(p, d->liver_right_c, d->liver_right_r) <= 1 || ellipsoid(p, d->liver_left_c, d->liver_left_r) <= 1) {
          l = TX_LAGB_LIVER;
        } else {
          double q[3] = {p[0] - d->spleen_c[0], p[1] - d->spleen_c[1], p[2] - d->spleen_c[2]};
          double a = (q[0] * su[0] + q[1] * su[1] + q[2] * su[2]) / d->spleen_r[0];
          double b = (q[0] * sb[0] + q[1] * sb[1] + q[2] * sb[2]) / d->spleen_r[1];
          double t = (q[0] * st[0] + q[1] * st[1] + q[2] * st[2]) / d->spleen_r[2];
          if (a * a + b * b + t * t <= 1) {
            l = TX_LAGB_SPLEEN;
          } else if (p[0] < 0.08 && p[2] > -0.11 && p[2] < 0.15) {
            for (int i = 0; i < ns; i++) {
              double dx = p[0] - sweep[i][0], dy = p[1] - sweep[i][1], dz = p[2] - sweep[i][2];
              if (dx * dx + dy * dy + dz * dz <= sweep[i][3] * sweep[i][3]) {
                l = TX_LAGB_STOMACH;
                break;
              }
            }
          }
        }
        v->label[((int64_t)z * n[1] + y) * n[0] + x] = l;
      }
  return true;
}

// ---- raw voxels with a JSON header

static bool json_vec3(json_t* root, const char* key, double out[3], bool required, const char* path) {
  json_t* a = json_object_get(root, key);
  if (!a) {
    if (required) tx_set_error("%s: key \"%s\" is missing", path, key);
    return !required;
  }
  if (!json_is_array(a) || json_array_size(a) != 3) {
    tx_set_error("%s: key \"%s\" must be an array of three numbers", path, key);
    return false;
  }
  for (int k = 0; k < 3; k++) {
    json_t* x = json_array_get(a, (size_t)k);
    if (!json_is_number(x) || !isfinite(json_number_value(x))) {
      tx_set_error("%s: key \"%s\" must be an array of three numbers", path, key);
      return false;
    }
    out[k] = json_number_value(x);
  }
  return true;
}

bool tx_lagb_volume_read_json(const char* path, tx_lagb_volume* v, tx_lagb_label* labels, int max_labels,
                              int* nlabels) {
  *v = (tx_lagb_volume){0};
  if (nlabels) *nlabels = 0;
  json_error_t je;
  json_t* root = json_load_file(path, 0, &je);
  if (!root) {
    tx_set_error("%s:%d:%d: %s", path, je.line, je.column, je.text);
    return false;
  }
  bool ok = json_is_object(root);
  if (!ok) tx_set_error("%s: expected a JSON object", path);
  double size[3], origin[3] = {0, 0, 0};
  ok = ok && json_vec3(root, "size", size, true, path) && json_vec3(root, "spacing", v->spacing, true, path) &&
       json_vec3(root, "origin", origin, false, path);
  int n[3];
  for (int k = 0; ok && k < 3; k++) {
    if (size[k] != floor(size[k]) || size[k] < 1 || size[k] > 4096) {
      tx_set_error("%s: key \"size\" must hold whole numbers from 1 to 4096", path);
      ok = false;
    } else if (!(v->spacing[k] > 0 && v->spacing[k] < 1)) {
      tx_set_error("%s: key \"spacing\" must be in metres, each above 0 and below 1", path);
      ok = false;
    }
    n[k] = (int)size[k];
  }
  memcpy(v->origin, origin, sizeof origin);
  const char* type = ok ? json_string_value(json_object_get(root, "type")) : NULL;
  int bytes = 0;
  bool is_signed = false;
  if (ok) {
    if (type && strcmp(type, "uint8") == 0) bytes = 1;
    else if (type && strcmp(type, "uint16") == 0) bytes = 2;
    else if (type && strcmp(type, "int16") == 0) bytes = 2, is_signed = true;
    else {
      tx_set_error("%s: key \"type\" must be \"uint8\", \"uint16\" or \"int16\"", path);
      ok = false;
    }
  }
  bool big = false;
  json_t* endian = ok ? json_object_get(root, "endian") : NULL;
  if (endian) {
    const char* e = json_string_value(endian);
    if (e && strcmp(e, "big") == 0) big = true;
    else if (!e || strcmp(e, "little") != 0) {
      tx_set_error("%s: key \"endian\" must be \"little\" or \"big\"", path);
      ok = false;
    }
  }
  const char* data = ok ? json_string_value(json_object_get(root, "data")) : NULL;
  if (ok && (!data || !*data)) {
    tx_set_error("%s: key \"data\" must name the raw voxel file", path);
    ok = false;
  }
  json_t* lab = ok ? json_object_get(root, "labels") : NULL;
  if (lab) {
    const char* key;
    json_t* val;
    if (!json_is_object(lab)) {
      tx_set_error("%s: key \"labels\" must be an object of names and whole numbers", path);
      ok = false;
    } else {
      json_object_foreach(lab, key, val) {
        if (!json_is_integer(val) || json_integer_value(val) < 1 || json_integer_value(val) > 65535 ||
            strlen(key) == 0 || strlen(key) >= sizeof labels[0].name) {
          tx_set_error("%s: labels.%s must be a whole number from 1 to 65535 (names up to 31 characters)", path, key);
          ok = false;
          break;
        }
        if (labels && nlabels && *nlabels < max_labels) {
          snprintf(labels[*nlabels].name, sizeof labels[0].name, "%s", key);
          labels[(*nlabels)++].value = (int)json_integer_value(val);
        }
      }
    }
  }
  // the data file, relative to the header
  char raw[4096] = "";
  if (ok) {
    const char* slash = strrchr(path, '/');
    int dir = data[0] == '/' || !slash ? 0 : (int)(slash - path + 1);
    if (snprintf(raw, sizeof raw, "%.*s%s", dir, path, data) >= (int)sizeof raw) {
      tx_set_error("%s: key \"data\": path too long", path);
      ok = false;
    }
  }
  ok = ok && alloc_volume(v, n);
  if (ok) {
    FILE* f = fopen(raw, "rb");
    if (!f) {
      tx_set_error("%s: key \"data\": %s: %s", path, raw, strerror(errno));
      ok = false;
    } else {
      int64_t count = tx_lagb_volume_count(v);
      unsigned char buf[65536];
      int64_t done = 0;
      while (ok && done < count) {
        size_t want = (size_t)((count - done) * bytes < (int64_t)sizeof buf ? (count - done) * bytes : (int64_t)sizeof buf);
        if (fread(buf, 1, want, f) != want) {
          tx_set_error("%s: key \"data\": %s holds fewer than %lld voxels of %d bytes", path, raw, (long long)count,
                       bytes);
          ok = false;
          break;
        }
        for (size_t i = 0; i < want / (size_t)bytes; i++) {
          int val;
          if (bytes == 1) val = buf[i];
          else {
            unsigned lo = buf[2 * i + (big ? 1 : 0)], hi = buf[2 * i + (big ? 0 : 1)];
            unsigned u = hi << 8 | lo;
            val = is_signed ? (int)(int16_t)u : (int)u;
          }
          if (val < 0) {
            tx_set_error("%s: key \"data\": %s holds a negative label (%d)", path, raw, val);
            ok = false;
            break;
          }
          v->label[done++] = (uint16_t)val;
        }
      }
      if (ok && fgetc(f) != EOF) {
        tx_set_error("%s: key \"data\": %s holds more than %lld voxels of %d bytes", path, raw, (long long)count, bytes);
        ok = false;
      }
      fclose(f);
    }
  }
  json_decref(root);
  if (!ok) tx_lagb_volume_free(v);
  return ok;
}

bool tx_lagb_volume_write_json(const tx_lagb_volume* v, const char* path, const tx_lagb_label* labels, int nlabels) {
  // the raw file beside the header: PATH less ".json", plus ".raw"
  char raw[4096], part[4200];
  size_t len = strlen(path);
  if (len > 5 && strcmp(path + len - 5, ".json") == 0) len -= 5;
  if (len + 5 >= sizeof raw) {
    tx_set_error("%s: path too long", path);
    return false;
  }
  snprintf(raw, sizeof raw, "%.*s.raw", (int)len, path);
  snprintf(part, sizeof part, "%s.part", raw);
  uint16_t top = 0;
  for (int64_t i = 0; i < tx_lagb_volume_count(v); i++) top = v->label[i] > top ? v->label[i] : top;
  int bytes = top < 256 ? 1 : 2;
  FILE* f = fopen(part, "wb");
  if (!f) {
    tx_set_error("%s: %s", raw, strerror(errno));
    return false;
  }
  bool ok = true;
  for (int64_t i = 0; ok && i < tx_lagb_volume_count(v); i++) {
    unsigned char b[2] = {(unsigned char)(v->label[i] & 0xff), (unsigned char)(v->label[i] >> 8)};
    ok = fwrite(b, 1, (size_t)bytes, f) == (size_t)bytes;
  }
  ok = fclose(f) == 0 && ok;
  if (!ok || rename(part, raw) != 0) {
    remove(part);
    tx_set_error("%s: write failed", raw);
    return false;
  }
  json_t* root = json_object();
  json_t* lab = json_object();
  for (int i = 0; i < nlabels; i++) json_object_set_new(lab, labels[i].name, json_integer(labels[i].value));
  const char* base = strrchr(raw, '/');
  json_object_set_new(root, "size", json_pack("[iii]", v->n[0], v->n[1], v->n[2]));
  json_object_set_new(root, "spacing", json_pack("[fff]", v->spacing[0], v->spacing[1], v->spacing[2]));
  json_object_set_new(root, "origin", json_pack("[fff]", v->origin[0], v->origin[1], v->origin[2]));
  json_object_set_new(root, "type", json_string(bytes == 1 ? "uint8" : "uint16"));
  json_object_set_new(root, "endian", json_string("little"));
  json_object_set_new(root, "data", json_string(base ? base + 1 : raw));
  json_object_set_new(root, "labels", lab);
  snprintf(part, sizeof part, "%s.part", path);
  ok = json_dump_file(root, part, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(9)) == 0;
  json_decref(root);
  if (!ok || rename(part, path) != 0) {
    remove(part);
    tx_set_error("%s: write failed", path);
    return false;
  }
  return true;
}

// ---- NIfTI

#ifdef TX_HAVE_NIFTI
bool tx_lagb_have_nifti(void) { return true; }

bool tx_lagb_volume_read_nifti(const char* path, tx_lagb_volume* v) {
  *v = (tx_lagb_volume){0};
  nifti_set_debug_level(0);  // the library prints otherwise; the one line is ours
  nifti_image* nim = nifti_image_read(path, 1);
  if (!nim || !nim->data) {
    if (nim) nifti_image_free(nim);
    tx_set_error("%s: not a readable NIfTI volume", path);
    return false;
  }
  bool ok = true;
  if (nim->dim[0] < 3 || nim->nvox != nim->nx * nim->ny * nim->nz || nim->nx > 4096 || nim->ny > 4096 ||
      nim->nz > 4096) {
    tx_set_error("%s: expected one 3-D volume (dim = %lld x %lld x %lld x %lld)", path, (long long)nim->nx,
                 (long long)nim->ny, (long long)nim->nz, (long long)nim->nt);
    ok = false;
  }
  // spacing in metres; a file that names no unit is taken as millimetres
  double unit = nim->xyz_units == NIFTI_UNITS_METER ? 1.0 : nim->xyz_units == NIFTI_UNITS_MICRON ? 1e-6 : 1e-3;
  for (int k = 0; ok && k < 3; k++) {
    v->spacing[k] = fabs(nim->pixdim[k + 1]) * unit;
    if (!(v->spacing[k] > 0 && v->spacing[k] < 1)) {
      tx_set_error("%s: voxel size pixdim[%d] = %g is not a size", path, k + 1, nim->pixdim[k + 1]);
      ok = false;
    }
  }
  if (ok) {
    if (nim->sform_code > 0)
      for (int k = 0; k < 3; k++) v->origin[k] = nim->sto_xyz.m[k][3] * unit;
    else if (nim->qform_code > 0)
      for (int k = 0; k < 3; k++) v->origin[k] = nim->qto_xyz.m[k][3] * unit;
    int n[3] = {(int)nim->nx, (int)nim->ny, (int)nim->nz};
    ok = alloc_volume(v, n);
  }
  for (int64_t i = 0; ok && i < nim->nvox; i++) {
    double x;
    switch (nim->datatype) {
      case DT_UINT8: x = ((const uint8_t*)nim->data)[i]; break;
      case DT_INT8: x = ((const int8_t*)nim->data)[i]; break;
      case DT_UINT16: x = ((const uint16_t*)nim->data)[i]; break;
      case DT_INT16: x = ((const int16_t*)nim->data)[i]; break;
      case DT_INT32: x = ((const int32_t*)nim->data)[i]; break;
      case DT_UINT32: x = ((const uint32_t*)nim->data)[i]; break;
      case DT_FLOAT32: x = ((const float*)nim->data)[i]; break;
      case DT_FLOAT64: x = ((const double*)nim->data)[i]; break;
      default:
        tx_set_error("%s: voxel type %s is not a label type", path, nifti_datatype_string(nim->datatype));
        ok = false;
        continue;
    }
    // a scaled file stores labels through slope and intercept
    if (nim->scl_slope != 0 && isfinite(nim->scl_slope) && isfinite(nim->scl_inter))
      x = x * nim->scl_slope + nim->scl_inter;
    if (!(x >= 0 && x <= 65535 && x == floor(x))) {
      tx_set_error("%s: voxel %lld holds %g, not a label (a whole number from 0 to 65535)", path, (long long)i, x);
      ok = false;
      break;
    }
    v->label[i] = (uint16_t)x;
  }
  nifti_image_free(nim);
  if (!ok) tx_lagb_volume_free(v);
  return ok;
}

bool tx_lagb_volume_write_nifti(const tx_lagb_volume* v, const char* path) {
  int64_t dims[8] = {3, v->n[0], v->n[1], v->n[2], 1, 1, 1, 1};
  nifti_set_debug_level(0);
  nifti_image* nim = nifti_make_new_nim(dims, DT_UINT16, 1);
  if (!nim) {
    tx_set_error("%s: cannot make a NIfTI image", path);
    return false;
  }
  memcpy(nim->data, v->label, (size_t)tx_lagb_volume_count(v) * sizeof(uint16_t));
  nim->xyz_units = NIFTI_UNITS_MM;
  for (int k = 0; k < 3; k++) nim->pixdim[k + 1] = nim->dx = v->spacing[k] * 1e3;
  nim->dx = v->spacing[0] * 1e3, nim->dy = v->spacing[1] * 1e3, nim->dz = v->spacing[2] * 1e3;
  nim->qform_code = NIFTI_XFORM_SCANNER_ANAT;
  nim->quatern_b = nim->quatern_c = nim->quatern_d = 0;
  nim->qfac = 1;
  nim->qoffset_x = v->origin[0] * 1e3, nim->qoffset_y = v->origin[1] * 1e3, nim->qoffset_z = v->origin[2] * 1e3;
  nim->qto_xyz = nifti_quatern_to_dmat44(0, 0, 0, nim->qoffset_x, nim->qoffset_y, nim->qoffset_z, nim->dx, nim->dy,
                                         nim->dz, 1);
  // written aside and renamed: PART keeps the extension that picks compression
  char part[4200];
  const char* dot = strstr(path, ".nii");
  if (!dot) {
    nifti_image_free(nim);
    tx_set_error("%s: a NIfTI file name ends in .nii or .nii.gz", path);
    return false;
  }
  snprintf(part, sizeof part, "%.*s.part%s", (int)(dot - path), path, dot);
  bool ok = nifti_set_filenames(nim, part, 0, 1) == 0;
  if (ok) nifti_image_write(nim);
  nifti_image_free(nim);
  FILE* f = ok ? fopen(part, "rb") : NULL;
  ok = f != NULL;
  if (f) fclose(f);
  if (!ok || rename(part, path) != 0) {
    remove(part);
    tx_set_error("%s: write failed", path);
    return false;
  }
  return true;
}
#else
bool tx_lagb_have_nifti(void) { return false; }
bool tx_lagb_volume_read_nifti(const char* path, tx_lagb_volume* v) {
  *v = (tx_lagb_volume){0};
  tx_set_error("%s: this build reads no NIfTI (configure with libnifti2-dev, -DTX_WITH_NIFTI=ON)", path);
  return false;
}
bool tx_lagb_volume_write_nifti(const tx_lagb_volume* v, const char* path) {
  tx_set_error("%s: this build writes no NIfTI (configure with libnifti2-dev, -DTX_WITH_NIFTI=ON)", path);
  return false;
}
#endif
