// The trainer's panels: the run's controls (pause, resume, single step,
// reset, time scale) and what each controller does live (rate, jitter,
// deadlines missed), for the system tx_system_run is running.
#include "gui.h"

#include "../../controllers/system.h"

#include <tactus/model.h>

#include <GLFW/glfw3.h>
#include <math.h>
#include <stdio.h>

#define RATE_WINDOW_NS 500000000 // the live rate is counted over half a second
#define MAX_SHOWN 64             // controllers listed

static struct {
  tx_system* sys;                  // the one the rates below belong to
  int64_t since_ns;                // start of the current counting window
  uint64_t steps_then[MAX_SHOWN];  // each one's steps at since_ns
  double hz[MAX_SHOWN];            // over the last whole window
} live;

static void count_rates(tx_system* s, int n) {
  int64_t now = tx_mono_ns();
  if (live.sys != s) {
    live.sys = s;
    live.since_ns = now;
    for (int i = 0; i < n; i++) live.steps_then[i] = tx_system_live(s, i).steps, live.hz[i] = 0;
    return;
  }
  if (now - live.since_ns < RATE_WINDOW_NS) return;
  for (int i = 0; i < n; i++) {
    uint64_t steps = tx_system_live(s, i).steps;
    live.hz[i] = (double)(steps - live.steps_then[i]) * 1e9 / (double)(now - live.since_ns);
    live.steps_then[i] = steps;
  }
  live.since_ns = now;
}

bool tx_gui_control_key(int key) {
  tx_system* s = tx_system_running();
  if (!s) return false;
  switch (key) {
  case GLFW_KEY_P: // a line that cannot be logged is no reason to refuse the control
    (void)(tx_system_paused(s) ? tx_system_resume(s) : tx_system_pause(s));
    return true;
  case GLFW_KEY_N: (void)tx_system_step(s); return true;
  case GLFW_KEY_R: (void)tx_system_reset(s); return true;
  case GLFW_KEY_LEFT_BRACKET: (void)tx_system_set_time_scale(s, fmax(TX_TIME_SCALE_MIN, tx_system_time_scale(s) / 2)); return true;
  case GLFW_KEY_RIGHT_BRACKET: (void)tx_system_set_time_scale(s, fmin(1, tx_system_time_scale(s) * 2)); return true;
  default: return false;
  }
}

void tx_gui_panels(float eye_w, float eye_h) {
  tx_system* s = tx_system_running();
  (void)eye_h;
  if (!tx_gui_begin("tactus", eye_w - 312, 8, 304, 300)) {
    tx_gui_end();
    return;
  }
  if (!s) {
    tx_gui_text("no run");
    tx_gui_end();
    return;
  }
  bool paused = tx_system_paused(s);
  tx_gui_text("T %.3f s  %s  x%.2f", tx_system_sim_time(s), paused ? "PAUSED" : "running", tx_system_time_scale(s));
  if (tx_gui_button(paused ? "Resume (P)" : "Pause (P)")) (void)(paused ? tx_system_resume(s) : tx_system_pause(s));
  tx_gui_same_line();
  if (tx_gui_button("Step (N)")) (void)tx_system_step(s);
  tx_gui_same_line();
  if (tx_gui_button("Reset (R)")) (void)tx_system_reset(s);
  double scale = tx_system_time_scale(s);
  if (tx_gui_slider("time scale", &scale, TX_TIME_SCALE_MIN, 1, "x%.2f")) (void)tx_system_set_time_scale(s, scale);
  tx_gui_text("step = %.1f ms; resets %llu", tx_system_step_period(s) * 1e3, (unsigned long long)tx_system_resets_done(s));

  int n = tx_system_count(s);
  if (n > MAX_SHOWN) n = MAX_SHOWN;
  count_rates(s, n);
  if (tx_gui_header("Controllers", true) && tx_gui_table_begin("controllers", 5)) {
    static const char* const head[] = {"name", "Hz", "of", "jitter us", "missed"};
    tx_gui_table_row(head, 5);
    for (int i = 0; i < n; i++) {
      tx_live_stats st = tx_system_live(s, i);
      char hz[32], nominal[32], jitter[32], missed[32];
      snprintf(hz, sizeof hz, "%.0f", live.hz[i]);
      snprintf(nominal, sizeof nominal, "%g", tx_system_rate(s, i));
      snprintf(jitter, sizeof jitter, "%.0f", (double)st.jitter_ns * 1e-3);
      snprintf(missed, sizeof missed, "%llu", (unsigned long long)st.missed);
      const char* row[] = {tx_system_name(s, i), hz, nominal, jitter, missed};
      tx_gui_table_row(row, 5);
    }
    tx_gui_table_end();
  }
  tx_gui_end();
}
