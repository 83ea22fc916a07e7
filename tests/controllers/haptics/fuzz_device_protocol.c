// libFuzzer target for the device protocol's decoder: whatever arrives, the
// decoder returns an error or a packet, never reads past the input (ASan),
// and a packet it accepts encodes back to the very same bytes. Each input is
// tried as it is and again with its last four bytes made the right CRC, so
// that the checks behind the CRC are fuzzed as well.
#include "controllers/haptics/device_protocol.h"

#include <stdlib.h>
#include <string.h>

static void check(const uint8_t* data, size_t size, bool fix_crc) {
  // an exact-size copy, so that a read one past the end is caught
  uint8_t* buf = malloc(size ? size : 1);
  if (!buf) return;
  if (size) memcpy(buf, data, size);
  if (fix_crc && size >= TX_DP_CRC_SIZE) {
    uint32_t c = tx_dp_crc32(buf, size - TX_DP_CRC_SIZE);
    for (int i = 0; i < 4; i++) buf[size - TX_DP_CRC_SIZE + (size_t)i] = (uint8_t)(c >> (8 * i));
  }
  tx_dp_packet p;
  tx_dp_error e = tx_dp_decode(buf, size, &p);
  if (e == TX_DP_OK) {
    uint8_t again[TX_DP_MAX_SIZE];
    size_t n = tx_dp_encode(&p, again, sizeof again);
    if (n != size || memcmp(again, buf, size) != 0) abort();
    tx_dp_peer peer = {0};
    if (tx_dp_peer_accept(&peer, &p, true) == TX_DP_NEW_SESSION && tx_dp_peer_accept(&peer, &p, true) != TX_DP_STALE)
      abort(); // the same packet twice is never new twice
  } else if (e <= TX_DP_OK || e >= TX_DP_ERR_COUNT) {
    abort();
  }
  free(buf);
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  check(data, size, false);
  check(data, size, true);
  return 0;
}
