// Internal: the synthetic controller of the `rates` scenario, and its payload
// format (f32 values whose last one carries a checksum of the others).
#ifndef TX_SCENARIOS_RATES_WORKER_H
#define TX_SCENARIOS_RATES_WORKER_H

#include <tactus/controller.h>

extern const tx_controller_class tx_rates_worker;

void tx_rates_payload_fill(float* v, size_t values, double base);
bool tx_rates_payload_intact(const float* v, size_t values);

#endif
