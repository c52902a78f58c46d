"""Altitude-estimator tuning: sensor limits, filter noises, gates, the sonar's repeat tests."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class EstimatorParams:
    """Estimator tuning; sonar limits are the HC-SR04's (thesis sec. 5.2)."""

    # The driver's minimum range (RNGFND1_MIN, RNGFND_MIN_CM: 0.2 m on both firmwares; the
    # HC-SR04's own 2 cm by default). Below it the sensor is blind: a reading there is the
    # floor only while the vehicle stands on it; in the air it says nothing (see `airborne`).
    sonar_min_m: float = 0.02
    sonar_max_m: float = 4.0
    sonar_sigma_m: float = 0.01  # the HC-SR04's σ; tilt is corrected, late echoes re-timed
    # Both firmwares report the range in whole centimetres (3.2.1's RANGEFINDER is a float of
    # integer cm / 100, 4.x's DISTANCE_SENSOR a uint16 of cm): rounding adds a uniform error of
    # ±resolution/2, σ = resolution/√12 ≈ 0.29 cm, to the sensor's own noise. 0 for a float range.
    sonar_resolution_m: float = 0.01
    # What the driver's readings lack on average (its truncations): 3.2.1's analog sonar floors
    # the ADC's code, the millivolts and the centimetres, and reads 4.0 cm short on average
    # (steps of 5.9 cm: half a step, plus half a mV times RNGFND_SCALING, plus half a cm); the
    # real 3.2.1 read about 5 cm low at 1 m. Added to every reading. 0 for a rounding driver.
    sonar_bias_m: float = 0.0
    # The HC-SR04 pings at most every 50 ms (20 Hz). The telemetry stream repeats its latest
    # reading at the stream's rate (40 Hz here), and neither message says when the reading was
    # taken (DISTANCE_SENSOR's time_boot_ms is the send time), so the same value arriving sooner
    # than this after the last reading counted is the stream's repeat. 80 % of the period leaves
    # room for arrival jitter on the link.
    sonar_repeat_s: float = 0.04
    # A same value arriving later is a new ping that landed in the same centimetre, unless the
    # vehicle has, by the accelerometer, moved more than this since the value first
    # appeared: then the sensor has not replaced its reading (over carpet an echo is still out)
    # and the stream is repeating an old one. Resolution plus 2σ of the sensor's noise.
    sonar_stale_move_m: float = 0.03
    # ...plus this much per second the value has lasted: the accelerometer's own drift from a
    # velocity known to a few cm/s, so that a long steady hover keeps its readings
    sonar_stale_drift_mps: float = 0.03
    # Over carpet a silent sensor (an echo still out) and a steady one look alike in the
    # stream, and fusing a stale value as new pins the estimate to where the vehicle was. A
    # sonar that lately lost an echo in the air (carpet loses a fifth of them) or, after a
    # silence, read an altitude the vehicle had left, is doubted: for this long after, only a
    # changed value is a new reading (as all were before whole centimetres).
    sonar_doubt_s: float = 5.0
    # Per-sample vertical acceleration noise the Kalman filter assumes: the vibration on a 40 Hz
    # RAW_IMU (~0.5 m/s²) and some margin; (q/r)^¼ ≈ 7 rad/s against the sonar. The hold flies
    # on its own faster filter (control_accel_sigma_mps2): trusting the accelerometer less here
    # would widen the gates while coasting and let more carpet echoes through.
    accel_sigma_mps2: float = 0.7
    bias_walk_mps2_per_sqrt_s: float = 0.01
    initial_bias_sigma_mps2: float = 0.2
    gate_sigma: float = 4.0  # Kalman innovation gate, in innovation standard deviations
    gate_m: float = 0.3  # complementary filter's fixed innovation gate
    reacquire_count: int = 4  # rejected readings in the window needed to reset to the sonar
    reacquire_spread_m: float = 0.1  # max spread of those readings (steady sonar)
    reacquire_window_s: float = 3.0
    reacquire_min_s: float = 1.5  # rejections must last longer than the carpet's late echoes
    # "Reads steadily" is judged on the readings of this last stretch of the run: a run that
    # began with the vehicle moving (a climb past a drifted estimate, stopped by a table top)
    # must not keep the steady readings after it from counting
    reacquire_steady_s: float = 0.75
    # A run that has lasted reacquire_min_s is believed too when at least this many of its
    # readings of that last reacquire_min_s lie on one straight line in time (the vehicle
    # climbing or sinking past an estimate that drifted the other way):
    # a rejected sonar that moves steadily is no carpet's scatter either, and waiting for it
    # to stand still would wait for ever while the hold chases the drift
    reacquire_track_count: int = 8
    reacquire_track_rms_m: float = 0.02  # the line's residual: the sonar's noise and its cm
    late_gap_s: float = 0.15  # a new reading after a longer silence is a late echo...
    late_max_s: float = 1.4  # ...unless the silence outlasts any echo: then its ping is unknown
    late_sigma_m: float = 0.12  # extra noise of a late echo shifted by the estimated climb
    ping_jitter_s: float = 0.05  # a ping leaves within this of the reading before it
    history_s: float = 2.0  # estimate history kept to place late echoes at their ping time
    stale_after_s: float = 0.25  # no accepted sonar for longer: coasting on the accelerometer
    ground_alt_m: float = 0.10  # below this estimate a zero sonar reading means "on the floor"
    # ...unless the accelerometer alone (its bias-corrected reading integrated, leaking away
    # over climb_leak_s) says the vehicle climbs faster than this: then the zero is a lost echo.
    # Over carpet a fifth of the pings never return, and reading each such zero as the floor
    # pinned a lifting vehicle's estimate to it while the take-off ramp drove it into the
    # ceiling (lockstep copter4 carpet seed 32: 2.9 m, the estimate at 0.09 m).
    climb_vel_mps: float = 0.25
    climb_leak_s: float = 1.0
    rest_vel_sigma_mps: float = 0.01  # standing disarmed on the floor: velocity is 0 to this
    # MS5611: ~0.12 m white noise per reading; its offset to the floor height drifts slowly
    # (weather, temperature) and is learned against the sonar and at rest
    baro_sigma_m: float = 0.15
    baro_offset_walk_m_per_sqrt_s: float = 0.01
    baro_min_alt_m: float = 0.4  # below, rotor downwash off the floor biases it (unless disarmed)
    surface_step_m: float = 0.3  # a sonar range this far beyond the estimate: another surface
    sonar_offset_m: float = 0.0  # sonar mounted this far below the centre of gravity (body z)
    rest_alt_m: float = 0.0  # centre-of-gravity height when standing on the floor
    complementary_tc_s: float = 1.0  # T of the third-order filter (gains 3/T, 3/T², 1/T³)
    max_dt_s: float = 0.2  # longer gaps (a stalled link) are integrated as this at most
    # An accelerometer sample older than this (3.2.1's 25 Hz period and its jitter) says nothing
    # about now: through a telemetry gap the filter assumes no acceleration instead of
    # integrating the last sample's noise and vibration (±0.6 m/s²) for the whole gap.
    imu_stale_s: float = 0.06
    # The hold's own filter (gcs/estimation/control.py): acceleration noise that puts its
    # bandwidth, (q/r)^¼ ≈ 14 rad/s, well above the altitude loop's crossover. 4-8 m/s² held a
    # little tighter but its velocity, through the D term, doubled the throttle's noise (std
    # 42-50 us against 23, lockstep apm25 seed 3), and the last override a radio fade leaves
    # on the vehicle could then lift it 1.4 m before the firmware's failsafe took over.
    control_accel_sigma_mps2: float = 2.0
    # What the hold's filter propagates on, while the station flies the throttle: the
    # acceleration its last command asked for (through the motors' lag), corrected by the
    # accelerometer's reading averaged over this time constant. The rotors' vibration (about
    # 0.5 m/s² a sample at hover) then enters the filter a few times weaker, while whatever the
    # command does not explain (a heavier vehicle, a thrust curve other than the one assumed,
    # ground effect) still comes from the accelerometer within a second. Lockstep, 8 seeds,
    # 30 s at 1 m: std 1.15 -> 0.81 cm (apm25), 0.99 -> 0.70 cm (copter4), the throttle no
    # noisier; with a vehicle 17 % heavier, laggier motors and twice the thrust expo than the
    # station assumes, 1.43 -> 1.36 cm. 0 turns it off.
    command_blend_tc_s: float = 1.0
    command_lag_s: float = 0.05  # the rotors' first-order time constant, as the station assumes
    # When the link loses the sonar's records outright (no repeat, no refusal: nothing, while
    # the IMU's samples keep coming), the hold's filter coasts on the command this long before
    # it takes the estimator's state (a stream that stopped whole hands over at
    # stale_after_s: the vehicle that fell behind has not flown those commands yet). On
    # 3.2.1's 25 Hz RAW_IMU a few samples of aliased vibration can read +0.5 m/s² against a
    # vehicle the hold pushes down: taken at stale_after_s, the estimator's velocity had the
    # wrong sign and the hold pushed on into the floor (30 % lossy link, lockstep apm25 seed
    # 52: 11.9 cm low). bench/lossy_hold.py, seeds 1-60: worst 11.9 -> 8.2 cm, none over
    # 0.1 m; 1.0 s gave the same. Over carpet the sensor keeps sending (repeats while an echo
    # is out) and the estimator's barometer bridges better: coasting there too cost 2-3.5 cm of
    # the carpet campaign's worst RMS, so it does not.
    control_coast_s: float = 0.6

    def __post_init__(self) -> None:
        if not 0.0 <= self.sonar_min_m < self.sonar_max_m:
            raise ValueError("need 0 <= sonar_min_m < sonar_max_m")
        positive = ("sonar_sigma_m", "accel_sigma_mps2", "gate_sigma", "gate_m",
                    "complementary_tc_s", "max_dt_s", "control_accel_sigma_mps2",
                    "climb_vel_mps", "climb_leak_s", "reacquire_steady_s")
        for name in positive:
            if getattr(self, name) <= 0.0:
                raise ValueError(f"{name} must be > 0")
        for name in ("command_blend_tc_s", "command_lag_s", "sonar_resolution_m", "sonar_bias_m",
                     "sonar_repeat_s", "sonar_stale_move_m", "sonar_stale_drift_mps",
                     "sonar_doubt_s", "control_coast_s"):
            if getattr(self, name) < 0.0:
                raise ValueError(f"{name} must be >= 0")
        if self.reacquire_count < 2 or self.reacquire_track_count < 3:
            raise ValueError("reacquire_count must be >= 2 and reacquire_track_count >= 3")
        if self.reacquire_track_rms_m < 0.0:
            raise ValueError("reacquire_track_rms_m must be >= 0")
