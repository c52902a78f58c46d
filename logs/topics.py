"""Topic names `logs/` writes itself, and the station's topics its plots and summaries read.

The station's names are defined in `gcs/topics.py`; `logs/` may not import `gcs`, so the few it
reads are repeated here and kept equal by a test.
"""

from __future__ import annotations

# Written by the recorder itself.
LOG_TOPIC = "/log"
MAVLINK_RX_TOPIC = "/mavlink/rx"
MAVLINK_TX_TOPIC = "/mavlink/tx"
TF_TOPIC = "/tf"

# Written by the station (names as in gcs/topics.py).
ESTIMATE_TOPIC = "/gcs/estimate"
ALT_CONTROLLER_TOPIC = "/gcs/alt_controller"
RC_OVERRIDE_TOPIC = "/gcs/rc_override"
EVENTS_TOPIC = "/gcs/events"
LINK_EVENTS_TOPIC = "/link/events"
RANGEFINDER_TOPIC = "/vehicle/rangefinder"
SIM_TRUTH_TOPIC = "/vehicle/sim_truth"
IMU_TOPIC = "/vehicle/imu"
HEARTBEAT_TOPIC = "/vehicle/heartbeat"
