#!/usr/bin/env python3
"""Builds robots/meshes/ from the official robot description packages on PyPI.

Sources (downloaded with pip, unpacked with unzip; the wheels are not committed):

    pip download --no-deps example-robot-data==6.0.0 -d /tmp/meshsrc
    (cd /tmp/meshsrc && mkdir erd && cd erd && unzip -q ../example_robot_data-6.0.0-*.whl)
    pip download --no-deps drake==1.14.0 --only-binary=:all: --python-version 3.11 \
        --platform manylinux_2_31_x86_64 -d /tmp/meshsrc/drake
    (cd /tmp/meshsrc/drake && unzip -q drake-1.14.0-*.whl \
        'pydrake/share/drake/manipulation/models/iiwa_description/*' \
        pydrake/doc/drake/LICENSE.TXT)

- UR5: example-robot-data 6.0.0, robots/ur_description/meshes/ur5 (ros-industrial
  universal_robot, kinetic-devel ur_description, BSD): visual .dae and collision .stl,
  copied byte for byte.
- Panda: example-robot-data 6.0.0, robots/panda_description/meshes (frankaemika franka_ros
  franka_description, Apache-2.0): visual .dae and collision .stl, copied byte for byte.
- iiwa 14: drake 1.14.0 wheel, pydrake/share/drake/manipulation/models/iiwa_description/meshes
  (the LBR iiwa 14 R820 meshes of drake's iiwa14_*.urdf, from IFL-CAMP/iiwa_stack, BSD):
  visual .obj copied byte for byte; the collision .obj meshes (iiwa_stack's collision STLs
  that drake converted to OBJ, 3 300-11 400 triangles each) are written back as binary STL
  (float32: lossless for OBJ's 6 decimals), 2.3 MB for the eight instead of 4.8 MB.
  `--collision-faces N` decimates them to at most N triangles instead (quadric decimation,
  PyPI fast-simplification through trimesh); not used for the bundled files, because
  4 000 triangles already moved thin features by up to 6.5 mm. The script prints, per
  mesh, the face counts and the largest distance from an original vertex to the written
  surface.

Run with a venv holding PyPI trimesh, fast-simplification, rtree and scipy:

    python3 -m venv /tmp/meshvenv
    /tmp/meshvenv/bin/pip install trimesh fast-simplification rtree scipy
    /tmp/meshvenv/bin/python tools/meshes/bundle_meshes.py \
        --erd /tmp/meshsrc/erd --drake /tmp/meshsrc/drake --out robots/meshes
"""

import argparse
import glob
import os
import shutil

import numpy as np
import trimesh

ERD_ROBOTS = "cmeel.prefix/share/example-robot-data/robots"
DRAKE_IIWA = "pydrake/share/drake/manipulation/models/iiwa_description"


def copy_all(pattern, dest):
    os.makedirs(dest, exist_ok=True)
    files = sorted(glob.glob(pattern))
    if not files:
        raise SystemExit(f"nothing matches {pattern}")
    for f in files:
        shutil.copyfile(f, os.path.join(dest, os.path.basename(f)))
    return files


def decimate_to_stl(src, dest, faces):
    """`src` as binary STL, decimated to at most `faces` triangles unless `faces` is None.
    Returns (faces before, faces after, max distance original vertex -> new surface)."""
    mesh = trimesh.load(src, force="mesh", process=True)
    before = len(mesh.faces)
    out = mesh
    if faces is not None and before > faces:
        out = mesh.simplify_quadric_decimation(face_count=faces)
    _, dist, _ = trimesh.proximity.closest_point(out, mesh.vertices)
    with open(dest, "wb") as fh:
        fh.write(trimesh.exchange.stl.export_stl(out))
    return before, len(out.faces), float(np.max(dist))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--erd", required=True, help="unpacked example-robot-data wheel")
    ap.add_argument("--drake", required=True, help="unpacked drake wheel")
    ap.add_argument("--out", required=True, help="robots/meshes")
    ap.add_argument("--collision-faces", type=int, default=None,
                    help="decimate the iiwa collision meshes to at most this many triangles")
    a = ap.parse_args()
    erd = os.path.join(a.erd, ERD_ROBOTS)

    for kind in ("visual", "collision"):
        copy_all(f"{erd}/ur_description/meshes/ur5/{kind}/*", f"{a.out}/ur5/{kind}")
        copy_all(f"{erd}/panda_description/meshes/{kind}/*", f"{a.out}/panda/{kind}")
    shutil.copyfile(f"{erd}/panda_description/LICENSE", f"{a.out}/panda/LICENSE")

    iiwa = os.path.join(a.drake, DRAKE_IIWA)
    copy_all(f"{iiwa}/meshes/visual/*.obj", f"{a.out}/iiwa14/visual")
    shutil.copyfile(f"{iiwa}/LICENSE.TXT", f"{a.out}/iiwa14/DRAKE_NOTICE.txt")
    shutil.copyfile(f"{iiwa}/iiwa_stack.LICENSE.txt", f"{a.out}/iiwa14/LICENSE")
    shutil.copyfile(f"{a.drake}/pydrake/doc/drake/LICENSE.TXT", f"{a.out}/iiwa14/DRAKE_LICENSE.txt")
    shutil.copyfile(f"{a.erd}/example_robot_data-6.0.0.dist-info/licenses/LICENSE",
                    f"{a.out}/ur5/EXAMPLE_ROBOT_DATA_LICENSE")
    os.makedirs(f"{a.out}/iiwa14/collision", exist_ok=True)
    for k in range(8):
        src = f"{iiwa}/meshes/collision/link_{k}.obj"
        dest = f"{a.out}/iiwa14/collision/link_{k}.stl"
        before, after, dev = decimate_to_stl(src, dest, a.collision_faces)
        print(f"iiwa14 collision link_{k}: {before} -> {after} triangles, "
              f"max vertex deviation {dev * 1000:.2f} mm")


if __name__ == "__main__":
    main()
