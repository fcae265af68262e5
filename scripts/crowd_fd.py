"""The fundamental diagram of our crowd against real walking (issue 41), for `make crowd-fd`.

The same corridor experiment twice, from the same start: `examples/crowd_corridor.rs` writes
our boids' trajectories, the city's street walkers' (the model people.motion = "boids" builds
walk) and their starting places and speeds; JuPedSim (collision-free speed
model, Tordeux et al. 2016) walks the same agents, from the same places at the same desired
speeds, to the corridor's far end. PedPy measures both the same way: density (people in the
measurement area / its area) and mean speed there, frame by frame. Weidmann's (1993)
empirical relation is drawn over both.

Usage: python scripts/crowd_fd.py <dir with boids_*.txt and start_*.csv> <picture.png>
       [length width seconds]
Prints a table (density bins: mean speed of each source) and writes the picture.
"""

import csv
import math
import pathlib
import sys

import jupedsim as jps
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402
import pedpy  # noqa: E402
from shapely import Polygon  # noqa: E402

# The measurement area: 4 m in the middle of where the crowd stands at the start, so it sees
# every density from the start's down to free walking as the crowd sets out and thins.
MA_FROM, MA_TO = 10.0, 14.0
FRAME_RATE = 2.0  # our boids' dt = 0.5 s; JuPedSim's frames are thinned to match
JPS_DT = 0.01
RADIUS = 0.2  # JuPedSim's agents (metres)


def weidmann(rho, v0=1.34, gamma=1.913, rho_max=5.4):
    """Weidmann (1993): walking speed at density rho (persons per square metre)."""
    return v0 * (1.0 - math.exp(-gamma * (1.0 / rho - 1.0 / rho_max)))


def measure(traj, width):
    """Per frame with someone in the measurement area: (density, mean speed)."""
    ma = pedpy.MeasurementArea([(MA_FROM, 0), (MA_TO, 0), (MA_TO, width), (MA_FROM, width)])
    density = pedpy.compute_classic_density(traj_data=traj, measurement_area=ma)
    speed = pedpy.compute_individual_speed(
        traj_data=traj, frame_step=1, speed_calculation=pedpy.SpeedCalculation.BORDER_SINGLE_SIDED
    )
    mean = pedpy.compute_mean_speed_per_frame(traj_data=traj, individual_speed=speed, measurement_area=ma)
    both = density.merge(mean, on="frame", how="inner")
    return both[both["density"] > 0]


def overlapping(traj):
    """The share of agent-frames with another agent's centre nearer than 2 x RADIUS (bodies
    of real shoulder width would overlap)."""
    import numpy as np

    hits = total = 0
    for _, f in traj.data.groupby("frame"):
        xy = f[["x", "y"]].to_numpy()
        if len(xy) < 2:
            continue
        d = np.hypot(xy[:, None, 0] - xy[None, :, 0], xy[:, None, 1] - xy[None, :, 1])
        np.fill_diagonal(d, np.inf)
        hits += int((d.min(axis=1) < 2 * RADIUS).sum())
        total += len(xy)
    return hits / max(total, 1)


def jupedsim_run(start, length, width, seconds, sqlite):
    """JuPedSim's walk of the agents of `start` to the corridor's far end."""
    area = Polygon([(0, 0), (length, 0), (length, width), (0, width)])
    sim = jps.Simulation(
        model=jps.CollisionFreeSpeedModel(),
        geometry=area,
        dt=JPS_DT,
        trajectory_writer=jps.SqliteTrajectoryWriter(
            output_file=sqlite, every_nth_frame=round(1.0 / (FRAME_RATE * JPS_DT)), commit_every_nth_write=1
        ),
    )
    exit_id = sim.add_exit_stage([(length - 1, 0), (length, 0), (length, width), (length - 1, width)])
    journey = sim.add_journey(jps.JourneyDescription([exit_id]))
    for row in start:
        # Inside the walls by the agent's radius (our boids are points).
        x = min(max(float(row["x"]), RADIUS + 0.01), length - RADIUS - 0.01)
        y = min(max(float(row["y"]), RADIUS + 0.01), width - RADIUS - 0.01)
        sim.add_agent(
            jps.CollisionFreeSpeedModelAgentParameters(
                journey_id=journey,
                stage_id=exit_id,
                position=(x, y),
                desired_speed=float(row["speed"]),
                radius=RADIUS,
            )
        )
    while sim.agent_count() > 0 and sim.elapsed_time() < seconds:
        sim.iterate()
    del sim  # the writer closes its file
    return pedpy.load_trajectory_from_jupedsim_sqlite(trajectory_file=sqlite)


def main():
    work, picture = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
    length, width, seconds = (float(a) for a in (sys.argv[3:6] if len(sys.argv) > 5 else (60, 4, 25)))
    points = {"edo-city boids": [], "edo-city street walkers": [], "JuPedSim": []}
    overlaps = []
    for traj_file in sorted(work.glob("boids_*.txt"), key=lambda p: float(p.stem.split("_")[1])):
        rho = traj_file.stem.split("_")[1]
        ours = pedpy.load_trajectory_from_txt(
            trajectory_file=traj_file, default_frame_rate=FRAME_RATE, default_unit=pedpy.TrajectoryUnit.METER
        )
        walkers = pedpy.load_trajectory_from_txt(
            trajectory_file=work / f"walkers_{rho}.txt",
            default_frame_rate=FRAME_RATE,
            default_unit=pedpy.TrajectoryUnit.METER,
        )
        with open(work / f"start_{rho}.csv", newline="") as f:
            start = list(csv.DictReader(f))
        sqlite = work / f"jupedsim_{rho}.sqlite"
        sqlite.unlink(missing_ok=True)
        theirs = jupedsim_run(start, length, width, seconds, sqlite)
        overlaps.append((rho, overlapping(ours), overlapping(walkers), overlapping(theirs)))
        for name, traj in (("edo-city boids", ours), ("edo-city street walkers", walkers), ("JuPedSim", theirs)):
            m = measure(traj, width)
            m["start"] = float(rho)
            points[name].append(m)
    frames = {k: pd.concat(v) for k, v in points.items()}

    # The table: mean speed per density bin of 0.5 persons/m2.
    bins = [0, 0.25, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 6.0]
    print("| density (1/m2) | Weidmann (m/s) | " + " | ".join(f"{k} (m/s, frames)" for k in frames) + " |")
    print("|---|---|" + "---|" * len(frames))
    for lo, hi in zip(bins, bins[1:]):
        mid = (lo + hi) / 2
        cells = []
        for f in frames.values():
            sel = f[(f["density"] > lo) & (f["density"] <= hi)]
            cells.append(f"{sel['speed'].mean():.2f} ({len(sel)})" if len(sel) else "-")
        print(f"| {lo}-{hi} | {weidmann(mid):.2f} | " + " | ".join(cells) + " |")

    print()
    print(f"| start density (1/m2) | agent-frames nearer than {2 * RADIUS} m: boids | street walkers | JuPedSim |")
    print("|---|---|---|---|")
    for rho, a, w, b in overlaps:
        print(f"| {rho} | {100 * a:.1f} % | {100 * w:.1f} % | {100 * b:.1f} % |")

    fig, ax = plt.subplots(figsize=(7, 4.5), dpi=110)
    colours = {"edo-city boids": "#c0392b", "edo-city street walkers": "#e67e22", "JuPedSim": "#2471a3"}
    for name, f in frames.items():
        ax.scatter(f["density"], f["speed"], s=9, alpha=0.45, color=colours[name], label=f"{name} (PedPy)")
    rho = [0.1 + 0.05 * i for i in range(100)]
    ax.plot(rho, [max(weidmann(r), 0) for r in rho], color="black", lw=2, label="Weidmann (1993)")
    ax.set_xlabel("density in the measurement area (persons / m²)")
    ax.set_ylabel("mean speed (m/s)")
    ax.set_xlim(0, 5)
    ax.set_ylim(0, 1.8)
    ax.set_title(f"Speed against density: a {length:g} x {width:g} m corridor, {MA_TO - MA_FROM:g} m measured")
    ax.grid(alpha=0.3)
    ax.legend(loc="upper right")
    fig.tight_layout()
    fig.savefig(picture)
    print(f"wrote {picture}")


if __name__ == "__main__":
    main()
