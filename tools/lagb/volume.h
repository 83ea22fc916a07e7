// The labelled volume of the LAGB asset pipeline: the procedural phantom of
// the upper abdomen, and a user's own segmentation read from NIfTI or from raw
// voxels with a JSON header. Errors: false and one line in tx_error().
//
// Frame (the phantom's, and what a header's spacing and origin mean): x to the
// patient's right, y anterior, z cranial (RAS), metres. A supine patient has y
// up, as the scene does.
#ifndef TX_TOOLS_LAGB_VOLUME_H
#define TX_TOOLS_LAGB_VOLUME_H

#include <stdbool.h>
#include <stdint.h>

// the labels of the phantom (a user's volume names its own in its header or
// on the command line)
enum { TX_LAGB_BACKGROUND = 0, TX_LAGB_LIVER = 1, TX_LAGB_STOMACH = 2, TX_LAGB_SPLEEN = 3, TX_LAGB_CAVITY = 4 };

typedef struct tx_lagb_volume {
  int n[3];           // voxels along x, y, z
  double spacing[3];  // voxel size along x, y, z, m
  double origin[3];   // centre of voxel (0, 0, 0), m
  uint16_t* label;    // labels (n[0] x n[1] x n[2]), x fastest
} tx_lagb_volume;

// the phantom's shapes: centres and semi-axes in m (the values and their
// sources are in assets/lagb/README.md)
typedef struct tx_lagb_phantom_def {
  double voxel;              // voxel size, m (the paper's 1.4 mm)
  double half[3];            // half extent of the volume, m
  double cavity_c[3];        // peritoneal cavity: centre, m
  double cavity_r[3];        // semi-axes, m
  double cavity_p;           // superellipsoid exponent (2: an ellipsoid)
  double liver_right_c[3];   // liver, right lobe: centre, m
  double liver_right_r[3];   // semi-axes, m
  double liver_left_c[3];    // liver, left lobe: centre, m
  double liver_left_r[3];    // semi-axes, m
  double stomach_scale;      // scales the stomach's centreline radii
  double spleen_c[3];        // spleen: centre, m
  double spleen_r[3];        // semi-axes (length, breadth, thickness), m
} tx_lagb_phantom_def;

tx_lagb_phantom_def tx_lagb_phantom_def_default(void);
bool tx_lagb_phantom(const tx_lagb_phantom_def* d, tx_lagb_volume* v);

void tx_lagb_volume_free(tx_lagb_volume* v);
int64_t tx_lagb_volume_count(const tx_lagb_volume* v);  // voxels

// a label name and its value, as a JSON header lists them
typedef struct tx_lagb_label {
  char name[32];
  int value;
} tx_lagb_label;

// raw voxels with a JSON header: {"size": [nx, ny, nz], "spacing": [dx, dy, dz]
// (m), "origin": [x, y, z] (m, optional), "type": "uint8" | "uint16" | "int16",
// "endian": "little" | "big" (optional), "data": "FILE" (relative to the
// header), "labels": {"liver": 1, ...} (optional)}. labels gets up to
// max_labels entries of the header's "labels".
bool tx_lagb_volume_read_json(const char* path, tx_lagb_volume* v, tx_lagb_label* labels, int max_labels,
                              int* nlabels);
// writes PATH (the header) and the raw file beside it, each aside then renamed
bool tx_lagb_volume_write_json(const tx_lagb_volume* v, const char* path, const tx_lagb_label* labels, int nlabels);

// NIfTI-1 or NIfTI-2 (.nii, .nii.gz): integer voxels, or floats that hold
// integers; false with a message when the build has no libnifti
bool tx_lagb_volume_read_nifti(const char* path, tx_lagb_volume* v);
bool tx_lagb_volume_write_nifti(const tx_lagb_volume* v, const char* path);
bool tx_lagb_have_nifti(void);

#endif
