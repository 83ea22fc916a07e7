// Internal: scenario files. A scenario is a JSON file naming controllers,
// their rates and parameters, optional model declarations and plugins; see
// docs/scenario-format.md. Every error is one line naming the file and the
// line:column (syntax) or the key (meaning), or the --set that caused it.
#ifndef TX_SCENARIOS_LOADER_H
#define TX_SCENARIOS_LOADER_H

#include "../controllers/system.h"

#include <limits.h>

typedef struct tx_scenario {
  char path[PATH_MAX];      // the file, or a label for text
  char name[TX_NAME_MAX];
  char description[256];
  double duration_s;        // default run length
  tx_system* system;        // finalized
} tx_scenario;

typedef struct tx_load_options {
  const char* const* sets;  // "KEY=VALUE" overrides, applied before checking
  int nsets;
  bool allow_plugins;       // false where the text is untrusted (the fuzzer)
  const char* const* devices; // --device specs, given in turn to the controllers of type "haptics"
  int ndevices;             // at most 2
  const char* view;         // "png" or "window" adds the graphics view; NULL or "none" only checks "view"
  const char* stereo;       // the view's stereo mode (mono, sbs, tb, anaglyph, lr), NULL for mono
  bool view_wait;           // lockstep: the view renders every tick instead of dropping frames
  const char* role;         // run only this role's controllers, and the bridge (docs/distributed.md); NULL: all
  const char* probe;        // "COMPONENT[,COMPONENT...][@EVERY_S]": add a view.probe of them (OUT/probe.csv); NULL: none
} tx_load_options;

// register the built-in controller classes (idempotent)
void tx_register_builtin(void);
// a scenario name from `tactus list`, or a path to a .json file, to a path;
// -1 with tx_error() when there is none
int tx_scenario_locate(const char* name_or_path, char* path, size_t size);
// NULL with the one-line message in tx_error()
tx_scenario* tx_scenario_load(const char* path, const tx_load_options* o);
tx_scenario* tx_scenario_load_text(const char* label, const char* text, size_t len, const tx_load_options* o);
// a document already parsed (a bench's changed copy of a scenario file), as
// if it were the file at path: its relative names are found beside it
tx_scenario* tx_scenario_load_json(const char* path, json_t* root, const tx_load_options* o);
void tx_scenario_free(tx_scenario* s);

// a file a scenario or study names (assets/needle/x.csv): as given when it is
// there, else a relative name in the source tree or its assets/ folder, so that
// tactus finds its own assets from any working folder; -1 if nowhere (path = given)
int tx_asset_locate(const char* given, char* path, size_t size);

// every scenario on the search path: $TACTUS_SCENARIO_PATH (':'-separated), then the source tree
typedef void (*tx_scenario_visit)(const char* name, const char* path, const char* description, void* user);
void tx_scenario_list(tx_scenario_visit visit, void* user);

#endif
