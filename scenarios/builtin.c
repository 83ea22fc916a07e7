// The controller classes that ship with tactus.
#include "loader.h"
#include "rates/rates_worker.h"

#include <tactus/config.h>

#include "../controllers/collision/hip_collision.h"
#include "../controllers/collision/wall.h"
#include "../controllers/haptics/haptics_controller.h"
#include "../controllers/voxel/needle_controller.h"
#include "../views/force_curve.h"
#include "../views/graphics/graphics_view.h"
#if TX_WITH_GLFW
#include "../views/graphics/window_input.h"
#endif
#if TX_WITH_BULLET
#include "../controllers/physics/skin_controller.h"
#endif

#include <pthread.h>

static void register_all(void) {
  tx_register_controller(&tx_rates_worker);
  tx_register_controller(&tx_collision_wall);
  tx_register_controller(&tx_collision_hip);
  tx_register_controller(&tx_view_force_curve);
  tx_register_controller(&tx_haptics_controller);
  tx_register_controller(&tx_voxel_needle_controller);
#if TX_WITH_OSMESA || TX_WITH_GLFW
  tx_register_controller(&tx_graphics_view);
#endif
#if TX_WITH_GLFW
  tx_register_controller(&tx_window_input);
#endif
#if TX_WITH_BULLET
  tx_register_controller(&tx_physics_skin);
#endif
}

void tx_register_builtin(void) {
  static pthread_once_t once = PTHREAD_ONCE_INIT;
  pthread_once(&once, register_all);
}
