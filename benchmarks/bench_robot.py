"""Speed of the batched robot evaluations against plain per-sample Pinocchio loops.

Run: ``python benchmarks/bench_robot.py [--n 20000]``. Prints per-configuration costs and
the speed-up ratios measured in the same run (the machines are shared and noisy: compare
ratios, not absolute times).
"""

from __future__ import annotations

import argparse

import numpy as np
import pinocchio as pin
from _results import figure, recorded  # benchmarks/_results.py
from _timing import best_of  # benchmarks/_timing.py

from adept_traj import Robot


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--n", type=int, default=20000, help="configurations per batch")
    args = parser.parse_args()
    robot = Robot.adept_one_xl()
    model, data = robot.model, robot.model.createData()
    rng = np.random.default_rng(0)
    lo, hi = robot.limits.lower, robot.limits.upper
    q = lo + (hi - lo) * rng.uniform(size=(args.n, robot.nq))
    v = rng.normal(size=q.shape)
    a = rng.normal(size=q.shape)
    fid = model.getFrameId(robot.tool_frame)

    def id_loop() -> np.ndarray:
        return np.array(
            [
                pin.rnea(model, data, qi, vi, ai)
                + model.damping * vi
                + model.friction * np.sign(vi)
                for qi, vi, ai in zip(q, v, a)
            ]
        )

    def w_loop() -> np.ndarray:
        out = np.empty(len(q))
        for k, qi in enumerate(q):
            jac = pin.computeFrameJacobian(model, data, qi, fid, pin.LOCAL_WORLD_ALIGNED)
            out[k] = abs(np.linalg.det(jac[[0, 1, 2, 5]]))
        return out

    def pose_loop() -> np.ndarray:
        out = np.empty((len(q), 4, 4))
        for k, qi in enumerate(q):
            pin.framesForwardKinematics(model, data, qi)
            out[k] = data.oMf[fid].homogeneous
        return out

    rows = [
        ("inverse_dynamics", lambda: robot.inverse_dynamics(q, v, a), id_loop),
        ("manipulability", lambda: robot.manipulability(q), w_loop),
        ("tool_pose", lambda: robot.tool_pose(q), pose_loop),
        ("geometry_poses (7 solids)", lambda: robot.geometry_poses(q), None),
    ]
    np.testing.assert_allclose(rows[0][1](), id_loop(), atol=1e-9)
    np.testing.assert_allclose(rows[1][1](), w_loop(), atol=1e-12)
    np.testing.assert_allclose(rows[2][1](), pose_loop(), atol=1e-12)
    print(f"batch of {args.n} configurations of {robot.name} (results checked equal)")
    print(f"{'operation':<28}{'batched µs/conf':>16}{'loop µs/conf':>14}{'speed-up':>10}")
    for name, batched, loop in rows:
        tb = best_of(batched) / args.n * 1e6
        if loop is None:
            print(f"{name:<28}{tb:>16.3f}{'-':>14}{'-':>10}")
            continue
        tl = best_of(loop, repeat=1) / args.n * 1e6
        print(f"{name:<28}{tb:>16.3f}{tl:>14.3f}{tl / tb:>9.1f}×")
        figure(name, f"{name}: batched vs a per-sample Pinocchio loop", round(tl / tb, 1), "×",
               note=f"batched {tb:.2f} µs, loop {tl:.2f} µs a configuration")  # fmt: skip


if __name__ == "__main__":
    with recorded(__file__, "the robot model: batched evaluations vs per-sample Pinocchio loops"):
        main()
