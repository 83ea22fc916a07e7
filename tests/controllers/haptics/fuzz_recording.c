// libFuzzer target for the recording reader (what `--device replay:FILE` and
// `tactus export` read): whatever the bytes, it returns an error or records
// that pass every check on read, never reads past the input (ASan), and its
// messages are one line. Each input is tried as it is and again with the
// header's and every block's CRC made right, so that the checks behind the
// CRCs are fuzzed as well.
#include "model/error.h"
#include "controllers/haptics/device_protocol.h"
#include "controllers/haptics/recorder.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static void fix_crcs(uint8_t* buf, size_t size) {
  tx_record_header h;
  if (size < sizeof h) return;
  memcpy(&h, buf, sizeof h);
  h.crc = 0;
  memcpy(buf, &h, sizeof h);
  h.crc = tx_dp_crc32(buf, sizeof h);
  memcpy(buf, &h, sizeof h);
  for (size_t off = sizeof h; size - off >= sizeof(tx_record_block);) {
    tx_record_block b;
    memcpy(&b, buf + off, sizeof b);
    size_t bytes = (size_t)b.count * sizeof(tx_record);
    if (b.count == 0 || b.count > TX_RECORD_BLOCK_MAX || size - off - sizeof b < bytes) return;
    b.crc = tx_dp_crc32(buf + off + 8, 8 + bytes);
    memcpy(buf + off, &b, sizeof b);
    off += sizeof b + bytes;
  }
}

static void one_line(const char* s) {
  if (strchr(s, '\n')) abort();
}

static void check(const uint8_t* data, size_t size, bool fix) {
  uint8_t* buf = malloc(size ? size : 1); // an exact-size copy, so that a read one past the end is caught
  if (!buf) return;
  if (size) memcpy(buf, data, size);
  if (fix) fix_crcs(buf, size);
  tx_record_file rf;
  tx_set_error("%s", "");
  int rc = tx_record_parse(buf, size, "fuzz.bin", &rf);
  const tx_record_header h = rf.header;
  tx_record* recs = rf.records;
  size_t count = rf.count;
  if (rc == 0) {
    if (count == 0 || !recs || *tx_error()) abort();
    one_line(rf.cut_short);
    for (size_t i = 0; i < count; i++) {
      const tx_record* r = &recs[i];
      if (i && !(r->t_s > recs[i - 1].t_s)) abort();
      for (int k = 0; k < 3; k++)
        if (!(fabs(r->pos[k]) <= 10) || !isfinite(r->vel[k]) || !(fabs(r->force[k]) <= h.device.max_force * 1.000001))
          abort();
    }
    free(recs);
  } else {
    if (recs || count || !*tx_error() || *rf.cut_short) abort();
    one_line(tx_error());
  }
  free(buf);
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  check(data, size, false);
  check(data, size, true);
  return 0;
}
