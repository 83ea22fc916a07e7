// net.dds: the bridge between the processes of a session (docs/distributed.md).
#ifndef TX_CONTROLLERS_NET_DDS_BRIDGE_H
#define TX_CONTROLLERS_NET_DDS_BRIDGE_H

#include <tactus/controller.h>

extern const tx_controller_class tx_net_dds_controller;

#endif
