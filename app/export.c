// tactus export: the CSV of a device recording, for a run that could not
// write it (killed, crashed, a full disk). Also the length of a recording,
// which a replay run takes as its duration.
#include "../scenarios/command.h"

#include "../controllers/haptics/recorder.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int tx_cmd_export(int argc, char** argv) {
  const char* bin = NULL;
  const char* out = NULL;
  for (int i = 1; i < argc; i++) {
    if (strcmp(argv[i], "--out") == 0) {
      if (++i == argc) return tx_bad_input("export: --out needs a FILE.csv");
      out = argv[i];
    } else if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
      return fputs("usage: tactus export FILE.bin [--out FILE.csv]\n"
                   "  writes the CSV of a device recording (default: FILE.csv beside it); a recording cut\n"
                   "  short by a killed run gives its whole records, with a warning\n",
                   stdout),
             0;
    } else if (argv[i][0] == '-' && argv[i][1]) {
      return tx_bad_input("export: unknown option '%s' (tactus export --help)", argv[i]);
    } else if (bin) {
      return tx_bad_input("export: unexpected argument '%s'", argv[i]);
    } else {
      bin = argv[i];
    }
  }
  if (!bin) return tx_bad_input("export: expected a recording FILE.bin (OUT/device0.bin of a run)");
  char csv[4200];
  size_t len = strlen(bin);
  if (out) snprintf(csv, sizeof csv, "%s", out);
  else if (len > 4 && strcmp(bin + len - 4, ".bin") == 0) snprintf(csv, sizeof csv, "%.*s.csv", (int)(len - 4), bin);
  else snprintf(csv, sizeof csv, "%s.csv", bin);
  if (strcmp(csv, bin) == 0) return tx_bad_input("export: --out %s is the recording itself", out);
  tx_record_file read;
  int rc = tx_record_export_csv(bin, csv, &read);
  if (rc == -1) return tx_bad_input("%s", tx_error()); // the recording is not one
  if (rc) return fprintf(stderr, "tactus: %s\n", tx_error()), 1;
  if (*read.cut_short) fprintf(stderr, "tactus: warning: %s\n", read.cut_short);
  printf("wrote %s\n", csv);
  return 0;
}

double tx_replay_duration(const char* const* devices, int ndevices, const char* const* sets, int nsets) {
  for (int i = 0; i < nsets; i++)
    if (strncmp(sets[i], "duration_s=", 11) == 0) return 0; // the user said how long
  double longest = 0;
  for (int i = 0; i < ndevices; i++) {
    if (strncmp(devices[i], "replay:", 7) != 0) continue;
    tx_record_file rf;
    if (tx_record_load(devices[i] + 7, &rf)) continue; // the loader says why
    tx_record_header h = rf.header;
    tx_record* recs = rf.records;
    size_t count = rf.count;
    // a replay plays record k at tick k after the first record's time (a
    // real-time recording may skip late ticks): the run covers every record
    double end = recs[0].t_s + (double)count / h.rate_hz;
    if (end > longest) longest = end;
    free(recs);
  }
  return longest;
}

void tx_replay_warn(tx_system* sys) {
  for (int i = 0; i < tx_system_count(sys); i++) {
    const char* spec = json_string_value(json_object_get(tx_system_params(sys, i), "device"));
    if (!spec || strncmp(spec, "replay:", 7) != 0) continue;
    tx_record_file rf;
    if (tx_record_load(spec + 7, &rf) == 0 && *rf.cut_short) fprintf(stderr, "tactus: warning: %s\n", rf.cut_short);
    free(rf.records);
  }
}
