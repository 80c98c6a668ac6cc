"""Every method on scanners other than the 180-degree SICK logs (a script, not a test; docs/formats.md, "Sensors").

Usage (from the checkout)::

    .venv/bin/python benchmarks/sensors_sweep.py make /tmp/sensors      # write one ROS2 bag per sensor
    .venv/bin/python benchmarks/sensors_sweep.py run /tmp/sensors -j 2  # albot1 run + evaluate every cell
    .venv/bin/python benchmarks/sensors_sweep.py table /tmp/sensors     # the Markdown table of the results

``make`` drives the office loop of ``synthetic-office-loop`` (plan, route, odometry error model) with each
scanner below, ray-cast with this repository's caster from the laser's own pose on the robot, and writes what
that scanner's ROS driver would publish as a ROS2 bag, written here with ``rosbags`` directly (not through
``albot1 convert``) so the LaserScan fields are the driver's: its ``angle_min``/``angle_increment`` (negative
for a clockwise scanner), ``range_min``/``range_max``, its way of saying "no return" (0, inf or NaN), its
rate (the robot's speed over the scan rate sets the spacing), and its mount as ``/tf_static``
(``base_link -> laser``, upside down as a roll of pi). ``/odom`` is the simulated odometry (the world's
error model, "noisy"), ``/ground_truth`` the exact pose. ``run`` runs each method through the CLI on each bag
as recorded and with ``?odometry=reference`` ("perfect"), scores the ATE (rigid alignment) with
``albot1 evaluate``, and writes one JSON line per cell to ``results.jsonl`` (a failure keeps its last
stderr line). Nothing is tuned: every method runs its default preset.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from albot1.data.synthetic import layouts, lidar
from albot1.data.synthetic.odometry import simulate
from albot1.data.synthetic.route import Sampling, sample, timestamps
from albot1.data.synthetic.worlds import OFFICE_ODOMETRY
from albot1.geometry.types import FloatArray

SEED = 105  # synthetic-office-loop's


@dataclass(frozen=True)
class Sensor:
    """A scanner as its driver publishes it, and how the robot carrying it drives."""

    name: str
    beams: int
    angle_min_deg: float  # of beam 0, in the laser's own frame
    increment_deg: float  # negative: a clockwise scanner
    range_min: float
    range_max: float
    rate_hz: float
    speed_mps: float
    turn_dps: float
    sigma_m: float  # range noise at 1 m
    sigma_rel: float  # plus this fraction of the range
    no_return: float  # what the driver writes for no echo: 0.0, inf or nan
    dropout: float = 0.0  # fraction of beams that read no_return at random (low-cost lidar)
    mount: tuple[float, float, float] = (0.0, 0.0, 0.0)  # x, y, yaw (rad) of the laser on the base
    upside_down: bool = False  # rolled by pi about its x axis

    @property
    def sampling(self) -> Sampling:
        return Sampling(
            step_m=self.speed_mps / self.rate_hz,
            step_deg=self.turn_dps / self.rate_hz,
            speed_mps=self.speed_mps,
            turn_rate_dps=self.turn_dps,
        )

    def laser_angles(self) -> FloatArray:
        """Beam angles (rad) in the laser's frame, in the driver's order."""
        return np.radians(self.angle_min_deg + self.increment_deg * np.arange(self.beams))


_UTM = {"beams": 1081, "angle_min_deg": -135.0, "increment_deg": 0.25, "range_min": 0.1, "range_max": 30.0}
_URG_STEP = 360.0 / 1024.0
_URG = {"beams": 682, "angle_min_deg": -340.5 * _URG_STEP, "increment_deg": _URG_STEP}
SENSORS = (
    Sensor("sick-180", 181, -90.0, 1.0, 0.0, 80.0, 5.0, 0.5, 45.0, 0.01, 0.0, math.inf),
    Sensor("lds01-360", 360, 0.0, 1.0, 0.12, 3.5, 5.0, 0.22, 45.0, 0.015, 0.02, 0.0, 0.05, (-0.032, 0.0, 0.0)),
    Sensor("utm30-270", **_UTM, rate_hz=40.0, speed_mps=1.5, turn_dps=90.0, sigma_m=0.01, sigma_rel=0.0,
           no_return=math.inf, mount=(0.2, 0.0, 0.0)),
    Sensor("utm30-270-cw", 1081, 135.0, -0.25, 0.1, 30.0, 40.0, 1.5, 90.0, 0.01, 0.0, math.inf, 0.0, (0.2, 0.0, 0.0)),
    Sensor("utm30-270-yaw90", **_UTM, rate_hz=40.0, speed_mps=1.5, turn_dps=90.0, sigma_m=0.01, sigma_rel=0.0,
           no_return=math.inf, mount=(0.1, 0.05, math.pi / 2)),
    Sensor("urg04-240", **_URG, range_min=0.02, range_max=5.6, rate_hz=10.0, speed_mps=0.5, turn_dps=45.0,
           sigma_m=0.01, sigma_rel=0.01, no_return=math.nan, mount=(0.15, 0.0, 0.0)),
    Sensor("urg04-240-upside-down", **_URG, range_min=0.02, range_max=5.6, rate_hz=10.0, speed_mps=0.5,
           turn_dps=45.0, sigma_m=0.01, sigma_rel=0.01, no_return=math.nan, mount=(0.15, 0.0, 0.0),
           upside_down=True),
    # diagnostics (which property of a sensor costs accuracy): the SICK with the LDS-01's 3.5 m range, the LDS-01
    # (360 deg, its noise and dropouts) with the SICK's 80 m
    Sensor("sick-180-range3.5", 181, -90.0, 1.0, 0.0, 3.5, 5.0, 0.5, 45.0, 0.01, 0.0, math.inf),
    Sensor("lds01-360-range80", 360, 0.0, 1.0, 0.12, 80.0, 5.0, 0.22, 45.0, 0.015, 0.02, 0.0, 0.05, (-0.032, 0.0, 0.0)),
    # ... and without its noise and dropouts (the SICK's 1 cm): what is left is the 360-degree field of view
    Sensor("lds01-360-range80-clean", 360, 0.0, 1.0, 0.12, 80.0, 5.0, 0.22, 45.0, 0.01, 0.0, 0.0, 0.0,
           (-0.032, 0.0, 0.0)),
)  # fmt: skip
METHODS = (
    ("odometry", ()),
    ("albot1", ("--preset", "literal")),
    ("albot1", ("--preset", "thesis")),
    ("albot1", ("--preset", "exact")),
    ("albot1", ("--preset", "plus")),
    ("albot1-places", ()),
    ("kiss-icp", ()),
    ("gtsam-graph", ()),
    ("mrpt-icp", ()),
)
#: Run only when named (``--method mrpt-rbpf``): the particle filter is not in the default sweep.
EXTRA_METHODS = (("mrpt-rbpf", ()),)
ODOMETRY = (("noisy", ""), ("perfect", "?odometry=reference"))


def simulate_sensor(sensor: Sensor) -> dict[str, Any]:
    """Poses, odometry, stamps and the driver's ranges of the office loop seen by ``sensor``."""
    plan, route = layouts.office_plan(), layouts.office_loop()
    reference = sample(route, sensor.sampling)
    odometry = simulate(reference, OFFICE_ODOMETRY, seed=np.random.default_rng([SEED, 0]))
    stamps = timestamps(reference, sensor.sampling)
    mx, my, myaw = sensor.mount
    c, s = np.cos(reference[:, 2]), np.sin(reference[:, 2])
    laser_poses = np.column_stack(
        [reference[:, 0] + c * mx - s * my, reference[:, 1] + s * mx + c * my, reference[:, 2] + myaw]
    )
    own = sensor.laser_angles()
    # a beam at angle a of a laser rolled by pi points at -a in the plane (its y axis points right)
    planar = -own if sensor.upside_down else own
    order = np.argsort(planar)
    exact = np.empty((len(reference), sensor.beams))
    exact[:, order] = lidar.cast_many(plan.walls, laser_poses, planar[order], sensor.range_max)
    # noise drawn in the order of the beams on the plane, so a scanner listed clockwise or mounted upside down
    # gets the same noise on the same physical beam as its upright twin (and is read back as the same scans)
    rng = np.random.default_rng([SEED, 7])
    noise, chance = np.empty_like(exact), np.empty_like(exact)
    noise[:, order] = rng.normal(0.0, 1.0, size=exact.shape)
    chance[:, order] = rng.random(exact.shape)
    sigma = sensor.sigma_m + sensor.sigma_rel * np.nan_to_num(exact, nan=0.0)
    ranges = exact + noise * sigma
    lost = ~np.isfinite(ranges) | (ranges < sensor.range_min) | (ranges > sensor.range_max)
    if sensor.dropout:
        lost |= chance < sensor.dropout
    ranges[lost] = sensor.no_return
    return {"reference": reference, "odometry": odometry, "stamps": stamps, "ranges": ranges.astype(np.float32)}


def write_bag(sensor: Sensor, data: dict[str, Any], out: Path) -> None:
    """A ROS2 sqlite3 bag as the sensor's driver and a simulator would record it."""
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    t = ts.types
    Time, Header = t["builtin_interfaces/msg/Time"], t["std_msgs/msg/Header"]
    Vector3, Quaternion = t["geometry_msgs/msg/Vector3"], t["geometry_msgs/msg/Quaternion"]

    def header(ns: int, frame: str) -> Any:
        return Header(stamp=Time(sec=ns // 10**9, nanosec=ns % 10**9), frame_id=frame)

    def quat(yaw: float, roll: float = 0.0) -> Any:  # rotation Rz(yaw) * Rx(roll)
        cy, sy, cr, sr = math.cos(yaw / 2), math.sin(yaw / 2), math.cos(roll / 2), math.sin(roll / 2)
        return Quaternion(x=cy * sr, y=sy * sr, z=sy * cr, w=cy * cr)

    def odom(pose: FloatArray, ns: int, parent: str) -> Any:
        p = t["geometry_msgs/msg/Pose"](
            position=t["geometry_msgs/msg/Point"](x=float(pose[0]), y=float(pose[1]), z=0.0),
            orientation=quat(float(pose[2])),
        )
        zero = Vector3(x=0.0, y=0.0, z=0.0)
        return t["nav_msgs/msg/Odometry"](
            header=header(ns, parent),
            child_frame_id="base_link",
            pose=t["geometry_msgs/msg/PoseWithCovariance"](pose=p, covariance=np.zeros(36)),
            twist=t["geometry_msgs/msg/TwistWithCovariance"](
                twist=t["geometry_msgs/msg/Twist"](linear=zero, angular=zero), covariance=np.zeros(36)
            ),
        )

    inc = math.radians(sensor.increment_deg)
    a0 = math.radians(sensor.angle_min_deg)
    with Writer(out, version=8) as bag:
        c_static = bag.add_connection("/tf_static", "tf2_msgs/msg/TFMessage", typestore=ts)
        c_scan = bag.add_connection("/scan", "sensor_msgs/msg/LaserScan", typestore=ts)
        c_odom = bag.add_connection("/odom", "nav_msgs/msg/Odometry", typestore=ts)
        c_ref = bag.add_connection("/ground_truth", "nav_msgs/msg/Odometry", typestore=ts)
        ns0 = int(1.7e18)
        mx, my, myaw = sensor.mount
        mount = t["geometry_msgs/msg/TransformStamped"](
            header=header(ns0, "base_link"),
            child_frame_id="laser",
            transform=t["geometry_msgs/msg/Transform"](
                translation=Vector3(x=mx, y=my, z=0.2), rotation=quat(myaw, math.pi if sensor.upside_down else 0.0)
            ),
        )
        tf = t["tf2_msgs/msg/TFMessage"](transforms=[mount])
        bag.write(c_static, ns0, ts.serialize_cdr(tf, "tf2_msgs/msg/TFMessage"))
        for i, stamp in enumerate(data["stamps"]):
            ns = ns0 + int(round(float(stamp) * 1e9))
            scan = t["sensor_msgs/msg/LaserScan"](
                header=header(ns, "laser"),
                angle_min=a0,
                angle_max=a0 + inc * (sensor.beams - 1),
                angle_increment=inc,
                time_increment=1.0 / sensor.rate_hz / sensor.beams,
                scan_time=1.0 / sensor.rate_hz,
                range_min=sensor.range_min,
                range_max=sensor.range_max,
                ranges=data["ranges"][i],
                intensities=np.zeros(0, dtype=np.float32),
            )
            bag.write(c_scan, ns, ts.serialize_cdr(scan, "sensor_msgs/msg/LaserScan"))
            bag.write(c_odom, ns, ts.serialize_cdr(odom(data["odometry"][i], ns, "odom"), "nav_msgs/msg/Odometry"))
            bag.write(c_ref, ns, ts.serialize_cdr(odom(data["reference"][i], ns, "map"), "nav_msgs/msg/Odometry"))


def make(root: Path) -> None:
    root.mkdir(parents=True, exist_ok=True)
    for sensor in SENSORS:
        out = root / f"{sensor.name}.db3"
        if out.exists():
            continue
        data = simulate_sensor(sensor)
        write_bag(sensor, data, out)
        n = len(data["stamps"])
        print(f"{out}: {n} scans, {sensor.beams} beams, {data['stamps'][-1]:.1f} s", file=sys.stderr)


def _cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "albot1", *args], capture_output=True, text=True, check=False)


def _last_line(text: str) -> str:
    lines = [line for line in text.strip().splitlines() if line.strip()]
    return lines[-1] if lines else ""


def run_cell(root: Path, sensor: str, method: str, extra: tuple[str, ...], odo: str, query: str) -> dict[str, Any]:
    label = method + (f":{extra[1]}" if extra else "")
    cell: dict[str, Any] = {"sensor": sensor, "method": label, "odometry": odo}
    runs = root / "runs" / sensor / odo / label.replace(":", "-")
    start = time.monotonic()
    done = _cli("run", method, f"{root / (sensor + '.db3')}{query}", *extra, "--out", str(runs))
    cell["seconds"] = round(time.monotonic() - start, 1)
    cell["traceback"] = "Traceback" in done.stderr
    if done.returncode != 0:
        cell["error"] = _last_line(done.stderr)
        return cell
    warnings = [line for line in done.stderr.splitlines() if "warn" in line.lower() or "none of" in line]
    cell["warnings"] = warnings[:3]
    scored = _cli("evaluate", str(runs / "latest"), "--json")
    if scored.returncode != 0:
        cell["error"] = "evaluate: " + _last_line(scored.stderr)
        return cell
    metrics = json.loads(scored.stdout)
    cell["ate_rmse_m"] = (metrics.get("ate") or {}).get("rmse_m")
    cell["ate_first_m"] = (((metrics.get("ate") or {}).get("other_alignments") or {}).get("first") or {}).get("rmse_m")
    trajectory = np.loadtxt(runs / "latest" / "trajectory.tum", ndmin=2)
    cell["finite"] = bool(np.isfinite(trajectory).all())
    cell["poses"] = len(trajectory)
    return cell


def run(
    root: Path, jobs: int, sensors: list[str] | None, methods: list[str] | None, odometry: list[str] | None
) -> None:
    """Every cell not yet in ``results.jsonl`` (``sensors``, ``methods``, ``odometry``: only those)."""
    out = root / "results.jsonl"
    lines = out.read_text().splitlines() if out.exists() else []
    done = {(c["sensor"], c["method"], c["odometry"]) for c in map(json.loads, filter(None, lines))}
    cells = [
        (s.name, m, extra, odo, query)
        for s in SENSORS
        if not sensors or s.name in sensors
        for odo, query in ODOMETRY
        if not odometry or odo in odometry
        for m, extra in METHODS + (EXTRA_METHODS if methods else ())
        if (not methods or m + (f":{extra[1]}" if extra else "") in methods)
        and (s.name, m + (f":{extra[1]}" if extra else ""), odo) not in done
    ]
    with ThreadPoolExecutor(jobs) as pool, out.open("a") as sink:
        for cell in pool.map(lambda c: run_cell(root, *c), cells):
            line = json.dumps(cell)
            sink.write(line + "\n")
            sink.flush()
            print(line, flush=True)


def table(root: Path) -> str:
    cells = [json.loads(line) for line in (root / "results.jsonl").read_text().splitlines() if line.strip()]
    latest = {(c["sensor"], c["method"], c["odometry"]): c for c in cells}
    seen = {c["sensor"] for c in cells}
    sensors = [s.name for s in SENSORS if s.name in seen]
    methods = list(dict.fromkeys(c["method"] for c in cells))
    lines = []
    for odo in ("perfect", "noisy"):
        what = "(its own ATE is 0: no ratio)" if odo == "perfect" else "in brackets: ratio to the odometry's ATE"
        lines += [f"ATE RMSE (m, rigid alignment), {odo} odometry {what}", ""]
        lines += ["| method | " + " | ".join(sensors) + " |", "|---" * (len(sensors) + 1) + "|"]
        for m in methods:
            row = []
            for s in sensors:
                c, base = latest.get((s, m, odo)), latest.get((s, "odometry", odo))
                if c is None:
                    row.append("")
                elif "error" in c:
                    row.append("FAIL")
                else:
                    ate, ref = c["ate_rmse_m"], (base or {}).get("ate_rmse_m")
                    ratio = f" ({ate / ref:.2f})" if m != "odometry" and ref and ref > 1e-6 else ""
                    row.append(f"{ate:.3f}{ratio}" + ("" if c.get("finite", True) else " NaN"))
            lines.append(f"| {m} | " + " | ".join(row) + " |")
        lines.append("")
    for c in cells:
        if "error" in c:
            lines.append(f"- FAIL {c['sensor']} {c['method']} {c['odometry']}: {c['error']}")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("what", choices=("make", "run", "table"))
    parser.add_argument("root", type=Path)
    parser.add_argument("-j", "--jobs", type=int, default=1)
    parser.add_argument("--sensor", action="append", help="only this sensor (repeatable)")
    parser.add_argument("--method", action="append", help="only this method, e.g. albot1:thesis (repeatable)")
    parser.add_argument("--odometry", action="append", choices=[o for o, _ in ODOMETRY], help="only this odometry")
    args = parser.parse_args()
    os.environ.setdefault("PYTHONPATH", str(Path(__file__).resolve().parent.parent))
    if args.what == "make":
        make(args.root)
    elif args.what == "run":
        run(args.root, args.jobs, args.sensor, args.method, args.odometry)
    else:
        sys.stdout.write(table(args.root) + "\n")


if __name__ == "__main__":
    main()
