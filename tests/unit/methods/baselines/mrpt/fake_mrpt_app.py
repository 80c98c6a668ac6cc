"""A stand-in for MRPT's icp-slam / rbpf-slam, for testing the wrapper without MRPT.

Run as ``python fake_mrpt_app.py APP CONFIG.ini RAWLOG``. It writes the
output files the real applications write, for ``FAKE_MRPT_SCANS`` scans on
a straight line 0.5 m per scan (the tests' odometry), or misbehaves as
``FAKE_MRPT_MODE`` says: ``short`` (a scan missing), ``frozen`` (the path
never moves), ``jump`` (a 5 m teleport at scan 3), ``crash`` (an MRPT exception, status 255), ``signal`` (killed
by SIGSEGV), ``sleep`` (never ends, burning no CPU), ``burn`` (never ends, burning CPU), ``hog`` (grows its
memory). Its banner names MRPT ``FAKE_MRPT_VERSION`` (default 2.5.8); run with no arguments, it prints the
banner and its usage, as the real ones do.
"""

from __future__ import annotations

import os
import re
import signal
import sys
import time
from pathlib import Path


def main() -> None:
    app = sys.argv[1]
    version = os.environ.get("FAKE_MRPT_VERSION", "2.5.8")
    print(f"[x|INFO] {app} - Part of the MRPT\n MRPT C++ Library: MRPT {version} - Sources timestamp: x", flush=True)
    if len(sys.argv) < 4:  # as the real applications: the banner, then their usage as an exception, status 255
        print(f"==== MRPT exception ====\nMessage:  Usage: {app} <config_file> [dataset.rawlog]", file=sys.stderr)
        sys.exit(255)
    ini_path, rawlog = Path(sys.argv[2]), Path(sys.argv[3])
    mode = os.environ.get("FAKE_MRPT_MODE", "ok")
    scans = int(os.environ["FAKE_MRPT_SCANS"])
    ini = ini_path.read_text()
    out = Path(re.search(r"^logOutput_dir = (.*)$", ini, re.M).group(1))  # type: ignore[union-attr]
    out.mkdir()
    assert rawlog.is_file() and rawlog.stat().st_size > 0
    if mode == "crash":
        print("==== MRPT exception ====\nMessage:  Assert condition failed: fake", file=sys.stderr)
        sys.exit(255)
    if mode == "signal":
        os.kill(os.getpid(), signal.SIGSEGV)
    if mode == "sleep":
        time.sleep(60)
    if mode == "burn":
        while True:
            pass
    if mode == "hog":
        blocks = []
        while True:
            blocks.append(bytearray(20 * 1024 * 1024))
            time.sleep(0.01)
    n = scans - 1 if mode == "short" else scans
    step = 0.0 if mode == "frozen" else 0.5
    if app == "icp-slam":
        with (out / "log_estimated_path.txt").open("w") as f:
            for k in range(2 * n):
                # The real app logs in the odometry frame; this one starts at (10, 5) heading +y.
                x, y = 10.0, 5.0 + step * (k // 2)
                if mode == "jump" and k // 2 >= 3:
                    y += 5.0  # a teleport at scan 3
                f.write(f"{k} {x:.6f} {y:.6f} {1.570796:.6f}\n")
        with (out / "log_times.txt").open("w") as f:
            for k in range(2 * n):
                f.write(f"{0.5 + k % 2:.6f} {1 + k // 4}\n")
        (out / "_finalmaps_.txt_mrpt__maps__CSimplePointsMap_00.txt").write_text("11.0 5.0 0.0\n9.0 6.0 0.0\n")
    else:
        updated = [k % 2 == 0 for k in range(n)]
        with (out / "log_times.txt").open("w") as f:
            f.write("% time_step  execution_time(ms)  map_size(#frames)  frame_inserted?\n%----\n")
            for k in range(n):
                f.write(f"{k} {10.0 if updated[k] else 0.01:.6f} {1 + k // 2} {int(updated[k])}\n")
        with (out / "most_likely_path.txt").open("w") as f:
            f.write("0.000 0.000 0.000\n")
            for k in range(n):
                if updated[k]:
                    f.write(f"{step * k:.3f} {0.01:.3f} 0.000\n")  # 1 cm left of the odometry at updates
        with (out / "log_estimated_path.txt").open("w") as f:
            for k in range(n):
                f.write(f"{k} {step * k:.6f} 0.000000 0 0.000000 0 0 {100.0 + k:.6f}\n")
        with (out / "log_ParticlesStats.txt").open("w") as f:
            f.write("% time_step   #particles   ESS\n%----\n")
            for k in range(n):
                f.write(f"{k} 30 {0.5 + 0.01 * (k % 3):.6f}\n")
        import numpy as np
        from matplotlib import image

        grid = np.full((4, 6), 0.5)
        grid[0, 1] = 0.1  # occupied: row 0 is y_max
        grid[3, 5] = 0.0
        grid[2, 2] = 0.9  # free
        image.imsave(out / "finalMap_mrpt__maps__COccupancyGridMap2D_00.png", grid, cmap="gray", vmin=0, vmax=1)
        (out / "finalMap_mrpt__maps__COccupancyGridMap2D_00_limits.txt").write_text(
            "% Grid limits: [x_min x_max y_min y_max]\n-1.0 2.0 -1.0 1.0\n"
        )
    print("----------- **END** (total time: 1.250 sec) ---------")


if __name__ == "__main__":
    main()
