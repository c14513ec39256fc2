#!/usr/bin/env python3
"""Derived MotionBenchMaker folders for checking a planner change on scenes it was not tuned on.

MotionBenchMaker keeps four scenes per robot back (cage, bookshelf_tall, bookshelf_thin,
table_under_pick); they must not be looked at. These folders stress the same properties on
the shown scenes' own problems, so that a change tuned on the shown scenes can be checked
against obstacles it has not met:

- `thin_boards`: `bookshelf_small` with every board 12 mm thick instead of 40 mm (thin
  obstacles that sparse discrete checks step over);
- `tall_shelf`: `bookshelf_small` with two more boards, 0.3 m above the top and below the
  bottom, and side walls to match (more obstacles near the goals);
- `posts`: `table_pick` inside four 30 mm posts at 0.8 m from the base and rails joining their
  tops 1.95 m up (long thin obstacles around the whole workspace).

The requests are the shown ones; a start or goal that now collides makes its problem invalid
(both the VAMP anchor and `armsim plan` report those, and neither plans them).

    tools/plan_proxy_scenes.py ROBOT_DIR OUT_DIR
      ROBOT_DIR  e.g. ../shared/benchmarks/motion-planning/ur5
      OUT_DIR    gets thin_boards/, tall_shelf/, posts/ (sceneNNNN.yaml, requestNNNN.yaml)

Side by side with VAMP (the anchor beside the robot folders, as in the shared benchmark):

    tools/plan_proxy_scenes.py ../shared/benchmarks/motion-planning/ur5 /tmp/proxy/ur5
    ln -s "$PWD/../shared/benchmarks/motion-planning/vamp" /tmp/proxy/vamp
    PLAN_BENCH_DIR=/tmp/proxy PLAN_SCENES="thin_boards tall_shelf posts" tools/plan_vs_vamp.sh ur5 -- 3
"""
import copy
import math
import os
import shutil
import sys

import yaml

BOARD = 0.04
THIN = 0.012
RISE = 0.3
POST = 0.03
POST_AT = 0.8
POST_TOP = 1.95


def thin_boards(scene):
    for obj in scene["world"]["collision_objects"]:
        for prim in obj["primitives"]:
            if prim["type"] == "box":
                prim["dimensions"] = [THIN if abs(d - BOARD) < 1e-9 else d for d in prim["dimensions"]]
    return scene


def tall_shelf(scene):
    objs = scene["world"]["collision_objects"]
    extra = []
    for obj in objs:
        name = obj["id"]
        if name not in ("shelf_bottom", "shelf_top", "side_left", "side_right"):
            continue
        shifts = {"shelf_bottom": [-RISE], "shelf_top": [RISE]}.get(name, [-RISE, RISE])
        for dz in shifts:
            o = copy.deepcopy(obj)
            o["id"] = f"{name}_{'up' if dz > 0 else 'down'}"
            o["primitive_poses"][0]["position"][2] += dz
            extra.append(o)
    objs.extend(extra)
    return scene


def box_object(name, centre, size):
    return {
        "id": name,
        "primitives": [{"type": "box", "dimensions": list(size)}],
        "primitive_poses": [{"position": list(centre), "orientation": [0, 0, 0, 1]}],
    }


def posts(scene):
    objs = scene["world"]["collision_objects"]
    corners = [(POST_AT * math.cos(a), POST_AT * math.sin(a)) for a in (0.25 * math.pi + k * 0.5 * math.pi for k in range(4))]
    for k, (x, y) in enumerate(corners):
        objs.append(box_object(f"post{k}", (x, y, POST_TOP / 2), (POST, POST, POST_TOP)))
    for k in range(4):
        (x0, y0), (x1, y1) = corners[k], corners[(k + 1) % 4]
        along_x = abs(x1 - x0) > abs(y1 - y0)
        size = (abs(x1 - x0), POST, POST) if along_x else (POST, abs(y1 - y0), POST)
        objs.append(box_object(f"rail{k}", ((x0 + x1) / 2, (y0 + y1) / 2, POST_TOP), size))
    return scene


VARIANTS = {"thin_boards": ("bookshelf_small", thin_boards), "tall_shelf": ("bookshelf_small", tall_shelf), "posts": ("table_pick", posts)}


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    src, out = sys.argv[1], sys.argv[2]
    for variant, (base, change) in VARIANTS.items():
        d = os.path.join(out, variant)
        os.makedirs(d, exist_ok=True)
        for f in sorted(os.listdir(os.path.join(src, base))):
            path = os.path.join(src, base, f)
            if f.startswith("request"):
                shutil.copyfile(path, os.path.join(d, f))
            elif f.startswith("scene"):
                with open(path) as fh:
                    scene = yaml.safe_load(fh)
                with open(os.path.join(d, f), "w") as fh:
                    yaml.safe_dump(change(scene), fh, default_flow_style=None, sort_keys=False)


if __name__ == "__main__":
    main()
