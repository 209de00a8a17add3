"""Write the CAD-like meshes of the shipped example cell (``adept_traj/data/scenes/cell/``,
``docs/example-cell.md``): a table fixture (STL in millimetres, concave and closed), a
guard block (OBJ in metres), the conveyor's belt frame (STL in millimetres) and the jig on
the turntable (STL in millimetres), and the joint table of the second robot (``robot_a.csv``:
a second AdeptOne XL across the belt swinging its arm away from near the planned goal).
The scene file ``cell.toml`` beside them places them and sets the machines' motions. Run
from the repository root: ``python examples/make_cell.py`` (the files are shipped; this
script is how they were made).
"""

from __future__ import annotations

from pathlib import Path

from adept_traj.testing.cad_meshes import box_mesh, merge_meshes, table_mesh, write_stl

OUT = Path(__file__).resolve().parents[1] / "adept_traj" / "data" / "scenes" / "cell"


def write_obj(path: Path, vertices, triangles) -> None:
    """A Wavefront OBJ of the mesh (metres)."""
    with open(path, "w", encoding="ascii") as f:
        f.write("# adept_traj example cell: guard block (metres)\n")
        f.writelines(f"v {x:.6f} {y:.6f} {z:.6f}\n" for x, y, z in vertices)
        f.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in triangles)


#: The second robot's move (t [s], joint1 [rad], joint2 [rad], joint3 [m], joint4 [rad]):
#: its gripper waits over the belt, 0.18 m from the planned robot's goal, until 0.4 s and
#: swings away by 1.5 s, so that the planned robot may reach its goal only once the other has left.
ROBOT_A = (
    (0.0, 0.0, 0.89, 0.10, 0.0),
    (0.4, 0.0, 0.89, 0.10, 0.0),
    (0.9, 0.80, 1.20, 0.05, 0.8),
    (1.5, 1.60, 0.90, 0.00, 1.5),
)


def write_joint_table(path: Path, rows) -> None:
    """A joint trajectory CSV (header ``t,q_joint1,…``, as ``best_trajectory.csv``)."""
    lines = ["t,q_joint1,q_joint2,q_joint3,q_joint4"] + [",".join(map(repr, r)) for r in rows]
    path.write_text("\n".join(lines) + "\n", encoding="ascii")


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    # the fixture: a 0.4 m × 0.2 m table, 0.30 m high, frame at its footprint's centre
    v, t = table_mesh(top=(0.4, 0.2), height=0.30, thickness=0.04, leg=0.04, subdivisions=3)
    write_stl(OUT / "fixture.stl", v, t, scale=1000.0)
    # the guard: a 0.4 × 0.2 × 0.21 m block, frame at its centre
    v, t = box_mesh((0.4, 0.2, 0.21), subdivisions=4)
    write_obj(OUT / "guard.obj", v, t)
    # the belt frame: 1.2 m × 0.14 m × 0.08 m, frame at its centre
    v, t = box_mesh((1.2, 0.14, 0.08), subdivisions=6)
    write_stl(OUT / "belt.stl", v, t, scale=1000.0)
    # the turntable's jig: two posts on a plate, frame at the plate's centre
    plate = box_mesh((0.24, 0.24, 0.03), 2, (0.0, 0.0, 0.015))
    posts = [box_mesh((0.04, 0.04, 0.2), 2, (x, 0.0, 0.13)) for x in (-0.08, 0.08)]
    v, t = merge_meshes(plate, *posts)
    write_stl(OUT / "jig.stl", v, t, scale=1000.0)
    write_joint_table(OUT / "robot_a.csv", ROBOT_A)
    for p in sorted(OUT.iterdir()):
        print(f"wrote {p} ({p.stat().st_size} bytes)")


if __name__ == "__main__":
    main()
