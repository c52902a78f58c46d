"""What the flight controller reads of its IMU and barometer against what a station receives:
the same draws, the same bias, drift and ground effect, but the rotors' vibration mostly and
the barometer's conversion noise partly averaged out by the firmware's drivers; the station's
samples keep the whole of both (DESIGN's realism floor)."""

from __future__ import annotations

import numpy as np

from sitl.sensor_params import BaroParams, ImuParams
from sitl.sensors.baro import CONVERSIONS_PER_READ, BaroModel
from sitl.sensors.imu import ImuModel

AT_REST = (0.0, 0.0, -9.80665)


def test_the_firmware_reads_the_accelerometer_without_most_of_the_vibration() -> None:
    prm = ImuParams()
    imu = ImuModel(prm, np.random.default_rng(5))
    samples = [imu.sample(0.01 * k, AT_REST, (0.0, 0.0, 0.0), 0.6) for k in range(4000)]
    station = np.array([s.acc_b for s in samples])
    firmware = np.array([s.acc_fw_b for s in samples])
    vib = prm.acc_vibration_mps2_full * 0.6
    # the station's samples carry the white noise and the whole vibration, as before
    assert abs(np.std(station[:, 2]) - np.hypot(prm.acc_noise_mps2, vib)) < 0.03
    # the firmware's keep the white noise and the residue, and the same bias
    expected = np.hypot(prm.acc_noise_mps2, prm.vibration_residue * vib)
    assert abs(np.std(firmware[:, 2]) - expected) < 0.01
    assert np.allclose(firmware.mean(axis=0), station.mean(axis=0), atol=0.03)
    assert np.std(firmware[:, 2]) >= prm.acc_noise_mps2 * 0.9  # the sensor's own noise stays


def test_the_firmware_averages_the_baro_conversions_between_reads() -> None:
    prm = BaroParams()
    baro = BaroModel(prm, np.random.default_rng(7), origin_alt_amsl_m=100.0)
    samples = [baro.sample(0.1 * k, 1.5, 1.5, 0.4) for k in range(3000)]
    station = np.array([s.alt_m for s in samples])
    firmware = np.array([s.alt_fw_m for s in samples])
    # one conversion each (differences cancel the slow drift): sigma 0.12 m, as before
    assert abs(np.std(np.diff(station)) / np.sqrt(2.0) - prm.noise_m) < 0.01
    ratio = np.std(np.diff(firmware)) / np.std(np.diff(station))  # drift cancels in diff
    assert abs(ratio - 1.0 / np.sqrt(CONVERSIONS_PER_READ)) < 0.02
    # the slow drift is in both: their difference is white noise about zero
    assert abs(float(np.mean(firmware - station))) < 0.01
