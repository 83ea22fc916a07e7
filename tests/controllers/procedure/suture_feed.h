// A scripted stand-in for the instruments and the thread of a suture
// ("test.suture_feed"), for the tests of procedure.suture and its scorecard:
// at script time t (the simulation's time divided by the parameter
// time_scale) it punctures in and out of the near edge (1.0, 1.2 s: z = 4
// and 0.5 mm) and the far edge (1.6, 2.0 s: z = -0.5 and -2.5 mm), pulls
// the thread through to a 2 cm tail (3 s), wraps it 1.5 turns around the
// holder's jaws (4 to 7 s), sends a knot (5 s), the knot fixed (5.5 s), a
// second knot (6.5 s) and a cut (7.5 s); the hands grasp at 0.5 and 0.7 s
// and let go at 8.0 and 8.5 s; hand 0 moves 10 cm along x over 8 s; the
// thread's tension rises to 2.5 N. Built into the test, and as a plugin
// (suture_feed_plugin) for sessions over several processes.
#ifndef TX_TESTS_SUTURE_FEED_H
#define TX_TESTS_SUTURE_FEED_H

#include <tactus/controller.h>

extern const tx_controller_class tx_test_suture_feed;

#endif
