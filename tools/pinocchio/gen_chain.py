#!/usr/bin/env python3
"""Generate a serial revolute chain URDF.

Usage: gen_chain.py N > chain_N.urdf

robot `chain_N`; links link0..linkN; revolute joints joint1..jointN.
joint i: parent link{i-1}, child link{i}; origin xyz "0 0 0.1" (joint1: "0 0 0"),
rpy "0 0 0"; axis cycles i%3==1 -> z, i%3==2 -> y, i%3==0 -> x;
limit lower -3.14159 upper 3.14159 effort 100 velocity 2.
link i>=1: inertial origin xyz "0 0 0.05", mass 1.0, ixx=iyy=0.01, izz=0.005,
zero products. link0 has no inertial.
"""
import sys

AXES = {1: "0 0 1", 2: "0 1 0", 0: "1 0 0"}


def chain(n: int) -> str:
    out = ['<?xml version="1.0"?>', f'<robot name="chain_{n}">', '  <link name="link0"/>']
    for i in range(1, n + 1):
        out += [
            f'  <link name="link{i}">',
            '    <inertial>',
            '      <origin xyz="0 0 0.05" rpy="0 0 0"/>',
            '      <mass value="1.0"/>',
            '      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.005"/>',
            '    </inertial>',
            '  </link>',
        ]
    for i in range(1, n + 1):
        xyz = "0 0 0" if i == 1 else "0 0 0.1"
        out += [
            f'  <joint name="joint{i}" type="revolute">',
            f'    <parent link="link{i - 1}"/>',
            f'    <child link="link{i}"/>',
            f'    <origin xyz="{xyz}" rpy="0 0 0"/>',
            f'    <axis xyz="{AXES[i % 3]}"/>',
            '    <limit lower="-3.14159" upper="3.14159" effort="100" velocity="2"/>',
            '  </joint>',
        ]
    out.append('</robot>')
    return "\n".join(out) + "\n"


if __name__ == "__main__":
    if len(sys.argv) != 2 or not sys.argv[1].isdigit() or int(sys.argv[1]) < 1:
        sys.exit("usage: gen_chain.py N > chain_N.urdf   (N >= 1)")
    sys.stdout.write(chain(int(sys.argv[1])))
