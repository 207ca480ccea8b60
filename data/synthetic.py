"""Small synthetic flights in ALFA's on-disk format: what the tests, the detector
checks (:mod:`alfa_bench.methods.contract`) and a plugin's own tests run on.

Roll and pitch follow a known first-order ARX law from their commands, airspeed
another, and the body rates (``imu-data_raw``, 10 Hz) a known law from the servo
outputs (``rc-out``, 3 Hz);
after the fault onset both laws change (the control surface stops answering), which
is the kind of change the detectors are built to see.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

T0_NS = 1_536_000_000_000_000_000
ATTITUDE_HEADER = ("%time,field.header.seq,field.header.stamp,field.header.frame_id,"
                   "field.commanded,field.measured")


def arx_response(u: np.ndarray, a: float, b: float, noise: np.ndarray) -> np.ndarray:
    """y(k) = a y(k-1) + b u(k) + noise(k)."""
    y = np.zeros_like(u)
    for k in range(1, u.size):
        y[k] = a * y[k - 1] + b * u[k] + noise[k]
    return y


def command(n: int, rate_hz: float, rng: np.random.Generator) -> np.ndarray:
    """A persistently exciting command: sum of sines plus piecewise-constant steps."""
    t = np.arange(n) / rate_hz
    steps = np.repeat(rng.uniform(-15, 15, size=n // 40 + 1), 40)[:n]
    return 10 * np.sin(0.5 * t) + 5 * np.sin(1.7 * t + 1) + steps


def attitude_rows(t_ns, commanded, measured) -> list[str]:
    seq = np.arange(t_ns.size) + 1000
    return [f"{t},{s},{t - 150_000},NED,{c!r},{m!r}"
            for t, s, c, m in zip(t_ns.tolist(), seq.tolist(), commanded.tolist(),
                                  measured.tolist(), strict=True)]


IMU_HEADER = ("%time,field.header.seq,field.header.stamp,field.header.frame_id,"
              "field.angular_velocity.x,field.angular_velocity.y,field.angular_velocity.z,"
              "field.linear_acceleration.x,field.linear_acceleration.y,"
              "field.linear_acceleration.z")

#: steps in the specific force at onset (m/s^2), by ground-truth topic: thrust lost, and
#: the sideslip of a stuck rudder
ACCEL_STEPS = {"failure_status-engines": (-1.5, 0.0), "failure_status-rudder": (0.0, 1.0)}
RC_HEADER = ("%time,field.header.seq,field.header.stamp,field.header.frame_id,"
             + ",".join(f"field.channels{i}" for i in range(8)))


VFR_HUD_HEADER = ("%time,field.airspeed,field.groundspeed,field.heading,field.throttle,"
                  "field.altitude,field.climb")

#: the rc-out channels ALFA's emulation freezes at onset, by ground-truth topic and code
EMULATED_CHANNELS = {("failure_status-engines", 1): [2], ("failure_status-elevator", 1): [1],
                     ("failure_status-rudder", 1): [3], ("failure_status-rudder", 2): [3],
                     ("failure_status-rudder", 3): [3], ("failure_status-aileron", 1): [5],
                     ("failure_status-aileron", 2): [4], ("failure_status-aileron", 3): [4, 5]}


def rate_topics(folder: Path, name: str, duration_s: float, onset_s: float | None,
                rng: np.random.Generator, emulation: tuple[str, int] | None = None,
                emulate_surfaces: bool = False, seed: int = 0) -> None:
    """rc-out at 3 Hz and the body rates at 10 Hz answering the held servo outputs:
    p = 2.5 da, q = 2 de, r(k) = 0.9 r(k-1) + 0.1 da (p and q stop answering at onset).

    Throttle (channel 2) and rudder (channel 3) move at random, and ``vfr_hud`` carries
    the throttle at 2.5 Hz, from a random stream of their own (``seed``). As ALFA's
    emulation does, the failed actuator of ``emulation`` (ground-truth topic, code)
    goes flat at onset: the throttle to idle (vfr_hud to 0), the rudder where it is;
    the elevator and aileron channels too with ``emulate_surfaces``.

    The specific force (same IMU rows, a stream of its own) is
    a_x = 0.5 + 0.3 sin(0.3 t), a_y = 0.5 r, a_z = -9.81, each plus noise, with the
    step of :data:`ACCEL_STEPS` from onset."""
    rc_t = np.arange(0.0, duration_s, 1 / 3)
    da = 0.3 * np.sin(0.8 * rc_t) + rng.uniform(-0.2, 0.2, rc_t.size)
    de = 0.2 * np.sin(0.5 * rc_t + 1) + rng.uniform(-0.2, 0.2, rc_t.size)
    pwm = np.full((rc_t.size, 8), 1500)
    pwm[:, 4] = pwm[:, 5] = np.round(1500 + 500 * da)
    pwm[:, 1] = np.round(1500 + 500 * de)
    own = np.random.default_rng(seed + 2000)
    pwm[:, 2] = np.round(1400 + 300 * own.uniform(size=rc_t.size))
    pwm[:, 3] = np.round(1500 + 200 * own.uniform(-1, 1, size=rc_t.size))
    hud_t = np.arange(0.2, duration_s, 0.4)
    throttle = np.round(own.uniform(0.3, 0.8, size=hud_t.size), 2)
    failed = EMULATED_CHANNELS.get(emulation, []) if onset_s is not None else []
    for ch in failed:
        if ch in (2, 3) or emulate_surfaces:
            after = rc_t >= onset_s
            pwm[after, ch] = 1100 if ch == 2 else pwm[np.argmax(after), ch]
    if 2 in failed:
        throttle[hud_t >= onset_s] = 0.0
    hud_ns = T0_NS + 4_000_000 + np.round(hud_t * 1e9).astype(np.int64)
    write_csv(folder / f"{name}-mavros-vfr_hud.csv", VFR_HUD_HEADER,
              [f"{t},0.0,15.0,90,{u!r},100.0,0.0"
               for t, u in zip(hud_ns.tolist(), throttle.tolist(), strict=True)])
    rc_ns = T0_NS + 2_000_000 + np.round(rc_t * 1e9).astype(np.int64)
    write_csv(folder / f"{name}-mavros-rc-out.csv", RC_HEADER,
              [f"{t},{i},{t - 100_000},," + ",".join(map(str, row))
               for i, (t, row) in enumerate(zip(rc_ns.tolist(), pwm.tolist(), strict=True))])
    imu_t = np.arange(0.5, duration_s, 0.1)
    held = np.searchsorted(rc_t, imu_t + 0.001, side="right") - 1
    gain = np.where(onset_s is not None and imu_t >= (onset_s or 0), 0.1, 1.0)
    p = gain * 2.5 * da[held] + rng.normal(0, 0.05, imu_t.size)
    q = gain * 2.0 * de[held] + rng.normal(0, 0.05, imu_t.size)
    r = arx_response(da[held], 0.9, 0.1, rng.normal(0, 0.01, imu_t.size))
    force = np.random.default_rng(seed + 3000)
    after = imu_t >= onset_s if onset_s is not None else np.zeros(imu_t.size, dtype=bool)
    step_x, step_y = ACCEL_STEPS.get(emulation[0] if emulation else None, (0.0, 0.0))
    ax = 0.5 + 0.3 * np.sin(0.3 * imu_t) + step_x * after + force.normal(0, 0.1, imu_t.size)
    ay = 0.5 * r + step_y * after + force.normal(0, 0.05, imu_t.size)
    az = -9.81 + force.normal(0, 0.2, imu_t.size)
    imu_ns = T0_NS + 3_000_000 + np.round(imu_t * 1e9).astype(np.int64)
    write_csv(folder / f"{name}-mavros-imu-data_raw.csv", IMU_HEADER,
              [f"{t},{i},{t - 100_000},base_link,{a!r},{b!r},{c!r},{d!r},{e!r},{g!r}"
               for i, (t, a, b, c, d, e, g) in enumerate(zip(
                   imu_ns.tolist(), p.tolist(), q.tolist(), r.tolist(), ax.tolist(),
                   ay.tolist(), az.tolist(), strict=True))])


def write_csv(path: Path, header: str, rows: list[str]) -> None:
    path.write_text("\n".join([header, *rows]) + "\n")


def write_flight(processed: Path, name: str, *, duration_s: float = 80.0, rate_hz: float = 20.0,
                 onset_s: float | None = None, fault_topic: str = "failure_status-engines",
                 code: int = 1, gt_rate_hz: float = 2.0, seed: int = 0,
                 emulate_surfaces: bool = False, switch_deg: float = 0.0) -> Path:
    """Write flight ``name`` under ``processed`` and return its folder.

    ``onset_s`` None writes a fault-free flight (no failure_status file). With
    ``emulate_surfaces`` the failed surface's servo channel goes flat at onset too.
    ``switch_deg`` is added to the roll and pitch commands from onset on, as ALFA's
    emergency trajectory switches them.
    """
    rng = np.random.default_rng(seed)
    folder = processed / name
    folder.mkdir(parents=True)
    n = int(duration_s * rate_hz)
    t_ns = T0_NS + np.round(np.arange(n) / rate_hz * 1e9).astype(np.int64) + 1_000_000
    faulty = np.zeros(n, dtype=bool) if onset_s is None else np.arange(n) / rate_hz >= onset_s
    for i, axis in enumerate(("roll", "pitch")):
        u = command(n, rate_hz, rng) / (i + 1) + switch_deg * faulty
        y = arx_response(u, 0.8, 0.2, rng.normal(0, 0.05, n))
        y_fault = arx_response(u, 0.8, 0.0, rng.normal(0, 0.05, n)) + 8.0
        measured = np.where(faulty, y_fault, y)
        write_csv(folder / f"{name}-mavros-nav_info-{axis}.csv", ATTITUDE_HEADER,
                  attitude_rows(t_ns + i * 3_000_000, u, measured))
    heading = np.random.default_rng(seed + 6000)
    yaw_cmd = 90.0 + np.cumsum(heading.normal(0, 0.5, n))
    write_csv(folder / f"{name}-mavros-nav_info-yaw.csv", ATTITUDE_HEADER,
              attitude_rows(t_ns + 7_000_000, yaw_cmd, yaw_cmd + heading.normal(0, 1.0, n)))
    rate_topics(folder, name, duration_s, onset_s, rng, (fault_topic, code), emulate_surfaces,
                seed)
    if onset_s is not None:
        gt_t = np.arange(onset_s, duration_s, 1 / gt_rate_hz)
        gt_ns = T0_NS + 1_000_000 + np.round(gt_t * 1e9).astype(np.int64)
        write_csv(folder / f"{name}-{fault_topic}.csv", "%time,field.data",
                  [f"{t},{code}" for t in gt_ns.tolist()])
    airspeed_topic(folder, name, t_ns + 5_000_000, rate_hz, np.random.default_rng(seed + 1000))
    errors_topic(folder, name, t_ns + 6_000_000, rate_hz, np.random.default_rng(seed + 4000))
    energy_topics(folder, name, duration_s, onset_s if fault_topic.endswith("engines") else None,
                  np.random.default_rng(seed + 5000))
    return folder


TWIST_HEADER = ("%time,field.header.seq,field.header.stamp,field.header.frame_id,"
                "field.twist.linear.x,field.twist.linear.y,field.twist.linear.z,"
                "field.twist.angular.x,field.twist.angular.y,field.twist.angular.z")
NAV_VELOCITY_HEADER = ("%time,field.header.seq,field.header.stamp,field.header.frame_id,"
                       "field.coordinate_frame,field.des_x,field.des_y,field.des_z,"
                       "field.meas_x,field.meas_y,field.meas_z")
#: what a lost engine does to the synthetic energy from onset: the climb rate falls by
#: this much (m/s) and the airspeed decays at this rate (m/s^2), down to 10 m/s
ENGINE_CLIMB_LOSS, ENGINE_SPEED_DECAY = 2.0, 0.5


def energy_topics(folder: Path, name: str, duration_s: float, engine_onset_s: float | None,
                  rng: np.random.Generator) -> None:
    """rel_alt, local_position-velocity (ENU) and nav_info-velocity (NED) at 4 Hz,
    wind_estimation at 2 Hz (ENU), m/s.

    The air-relative speed wanders about 16 m/s along a slowly turning heading, the
    climb rate about 0 (0.5 sin(0.1 t)), the wind holds (3, 2); the ground velocity is
    air plus wind and the height integrates the climb rate. From ``engine_onset_s`` the
    aircraft loses energy (:data:`ENGINE_CLIMB_LOSS`, :data:`ENGINE_SPEED_DECAY`)."""
    t = np.arange(0.3, duration_s, 0.25)
    after = (t - engine_onset_s).clip(0) if engine_onset_s is not None else np.zeros(t.size)
    speed = np.maximum(16.0 + 0.5 * np.sin(0.05 * t) - ENGINE_SPEED_DECAY * after, 10.0)
    climb = 0.5 * np.sin(0.1 * t) - ENGINE_CLIMB_LOSS * (after > 0) + rng.normal(0, 0.1, t.size)
    heading = 0.02 * t
    wind = (3.0, 2.0)
    east, north = speed * np.cos(heading) + wind[0], speed * np.sin(heading) + wind[1]
    height = 100.0 + np.cumsum(climb) * 0.25
    ns = T0_NS + 7_000_000 + np.round(t * 1e9).astype(np.int64)
    write_csv(folder / f"{name}-mavros-global_position-rel_alt.csv", "%time,field.data",
              [f"{a},{h!r}" for a, h in zip(ns.tolist(), height.tolist(), strict=True)])
    write_csv(folder / f"{name}-mavros-local_position-velocity.csv", TWIST_HEADER,
              [f"{a},{i},{a - 100_000},map,{e!r},{n!r},{c!r},0.0,0.0,0.0"
               for i, (a, e, n, c) in enumerate(zip(ns.tolist(), east.tolist(), north.tolist(),
                                                    climb.tolist(), strict=True))])
    # the autopilot's own estimate of the same ground velocity (nav_info, NED)
    write_csv(folder / f"{name}-mavros-nav_info-velocity.csv", NAV_VELOCITY_HEADER,
              [f"{a + 8_000_000},{i},{a},NED,5,0.0,0.0,0.0,{n!r},{e!r},{-c!r}"
               for i, (a, e, n, c) in enumerate(zip(ns.tolist(), east.tolist(), north.tolist(),
                                                    climb.tolist(), strict=True))])
    wt = t[::2]
    gust = rng.normal(0, 0.2, (wt.size, 2)) + wind
    write_csv(folder / f"{name}-mavros-wind_estimation.csv", TWIST_HEADER,
              [f"{a + 9_000_000},{i},{a},,{g[0]!r},{g[1]!r},0.0,0.0,0.0,0.0"
               for i, (a, g) in enumerate(zip(ns[::2].tolist(), gust.tolist(), strict=True))])


def airspeed_topic(folder: Path, name: str, t_ns: np.ndarray, rate_hz: float,
                   rng: np.random.Generator) -> None:
    """nav_info-airspeed: a first-order response to a stepped airspeed command (m/s),
    unaffected by the synthetic faults."""
    n = t_ns.size
    commanded = 15.0 + np.repeat(rng.uniform(-2, 2, size=n // 200 + 1), 200)[:n]
    measured = 15.0 + arx_response(commanded - 15.0, 0.95, 0.05, rng.normal(0, 0.05, n))
    write_csv(folder / f"{name}-mavros-nav_info-airspeed.csv", ATTITUDE_HEADER,
              attitude_rows(t_ns, commanded, measured))


ERRORS_HEADER = ("%time,field.header.seq,field.header.stamp,field.header.frame_id,"
                 "field.alt_error,field.aspd_error,field.xtrack_error,field.wp_dist")


def errors_topic(folder: Path, name: str, t_ns: np.ndarray, rate_hz: float,
                 rng: np.random.Generator) -> None:
    """nav_info-errors: an altitude error wandering about a flight's own offset (m)."""
    n = t_ns.size
    alt = rng.uniform(-10, 10) + arx_response(rng.normal(0, 1, n), 0.99, 0.05,
                                              np.zeros(n))
    # the airspeed error (cm/s) swings slowly about 0, drawn from no generator so that
    # every other synthetic value stays what it was
    aspd = 50.0 * np.sin(0.05 * (t_ns - T0_NS) * 1e-9)
    seq = np.arange(n) + 500
    write_csv(folder / f"{name}-mavros-nav_info-errors.csv", ERRORS_HEADER,
              [f"{t},{s},{t - 120_000},NED,{a!r},{v!r},0.0,10"
               for t, s, a, v in zip(t_ns.tolist(), seq.tolist(), alt.tolist(), aspd.tolist(),
                                     strict=True)])


def rename_flight(folder: Path, name: str) -> Path:
    """Rename flight ``folder`` and its files to ``name``; return the new folder."""
    new = folder.with_name(name)
    folder.rename(new)
    for f in new.iterdir():
        f.rename(new / f.name.replace(folder.name, name, 1))
    return new


def write_corpus(processed: Path) -> dict[str, Path]:
    """A small corpus: fault flights of several classes, fault-free, emr, late."""
    specs = {
        "carbonZ_2018-07-18-15-53-31_1_engine_failure": dict(onset_s=50.0),
        "carbonZ_2018-07-18-16-37-39_1_no_failure": dict(seed=1),
        "carbonZ_2018-07-30-16-29-45_engine_failure_with_emr_traj": dict(onset_s=55.0, seed=2),
        "carbonZ_2018-09-11-15-06-34_3_rudder_left_failure":
            dict(onset_s=45.0, fault_topic="failure_status-rudder", code=2, seed=3),
        "carbonZ_2018-10-05-14-37-22_2_right_aileron_failure":
            dict(onset_s=52.0, fault_topic="failure_status-aileron", code=1, seed=4),
        "carbonZ_2018-10-05-14-34-20_1_no_failure": dict(seed=5),
    }
    return {name: write_flight(processed, name, **kw) for name, kw in specs.items()}
