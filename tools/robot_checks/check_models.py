#!/usr/bin/env python3
"""Independent checks of the armsim robot model files in robots/.

Everything here is written from scratch with numpy (own TOML-schema validation, DH forward
kinematics, URDF parser + forward kinematics, Jacobian-based mass matrix and gravity vector), and is
cross-checked, when the packages are installed, against
  * Peter Corke's Robotics Toolbox for Python (`pip install roboticstoolbox-python`): Puma560,
    Stanford, Cobra600 and Panda DH models (FK, inertia matrix, gravity load);
  * Pinocchio (`pip install pin`): URDF parsing, FK, mass matrix and gravity of ur5/panda/iiwa14.

Usage:  python3 tools/robot_checks/check_models.py [--samples N] [--seed S]
Exit status 0 when every check passes (published-data exceptions that are documented in the model
files are reported as KNOWN and do not fail the run), 1 otherwise.

Conventions (docs/dh-format.md): standard DH  A_i = Rz(theta) Tz(d) Tx(a) Rx(alpha);
modified DH A_i = Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_i) Tz(d_i); URDF rpy: R = Rz(y) Ry(p) Rx(r).
"""
from __future__ import annotations

import argparse
import math
import os
import sys
import tomllib
import xml.etree.ElementTree as ET

import numpy as np

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
ROBOTS = os.path.join(ROOT, "robots")
TOL = 1e-12

# --------------------------------------------------------------------------------------------
# reporting
# --------------------------------------------------------------------------------------------
RESULTS: list[tuple[str, str, str]] = []  # (status, name, detail)


def report(status: str, name: str, detail: str = "") -> None:
    RESULTS.append((status, name, detail))
    print(f"[{status:5s}] {name}" + (f": {detail}" if detail else ""), flush=True)


def check(ok: bool, name: str, detail: str = "") -> bool:
    report("PASS" if ok else "FAIL", name, detail)
    return ok


# --------------------------------------------------------------------------------------------
# elementary transforms
# --------------------------------------------------------------------------------------------
def rotx(t):
    c, s = math.cos(t), math.sin(t)
    return np.array([[1.0, 0, 0], [0, c, -s], [0, s, c]])


def roty(t):
    c, s = math.cos(t), math.sin(t)
    return np.array([[c, 0, s], [0, 1.0, 0], [-s, 0, c]])


def rotz(t):
    c, s = math.cos(t), math.sin(t)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])


def rpy_to_R(r, p, y):
    """URDF fixed-axis roll-pitch-yaw: R = Rz(y) Ry(p) Rx(r)."""
    return rotz(y) @ roty(p) @ rotx(r)


def hom(R=None, p=None):
    T = np.eye(4)
    if R is not None:
        T[:3, :3] = R
    if p is not None:
        T[:3, 3] = p
    return T


def Rz4(t):
    return hom(rotz(t))


def Rx4(t):
    return hom(rotx(t))


def Tz4(d):
    return hom(p=[0, 0, d])


def Tx4(a):
    return hom(p=[a, 0, 0])


def axis_angle(axis, t):
    k = np.asarray(axis, float)
    k = k / np.linalg.norm(k)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(t) * K + (1 - math.cos(t)) * (K @ K)


def pose_err(A, B):
    """(max |dp|, max |dR_ij|) between two homogeneous transforms."""
    return float(np.max(np.abs(A[:3, 3] - B[:3, 3]))), float(np.max(np.abs(A[:3, :3] - B[:3, :3])))


def inertia_matrix(v):
    ixx, iyy, izz, ixy, ixz, iyz = v
    return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]], float)


# --------------------------------------------------------------------------------------------
# DH TOML: schema validation (docs/dh-format.md) and model
# --------------------------------------------------------------------------------------------
TOP_KEYS = {"name", "convention", "gravity", "base", "tool", "joint"}
FRAME_KEYS = {"xyz", "rpy", "rpy_deg"}
JOINT_KEYS = {"name", "type", "theta", "theta_deg", "d", "a", "alpha", "alpha_deg", "lower",
              "lower_deg", "upper", "upper_deg", "velocity", "effort", "continuous", "mass", "com",
              "inertia", "motor_inertia", "gear_ratio"}


def num(x):
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def validate_toml(path, doc):
    errs = []
    f = os.path.basename(path)
    for k in doc:
        if k not in TOP_KEYS:
            errs.append(f"{f}: unknown top-level key '{k}'")
    if doc.get("convention") not in ("standard", "modified"):
        errs.append(f"{f}: convention must be 'standard' or 'modified'")
    if not isinstance(doc.get("name"), str):
        errs.append(f"{f}: missing name")
    for sec in ("base", "tool"):
        if sec in doc:
            for k, v in doc[sec].items():
                if k not in FRAME_KEYS:
                    errs.append(f"{f}: [{sec}] unknown key '{k}'")
                elif not (isinstance(v, list) and len(v) == 3 and all(num(e) for e in v)):
                    errs.append(f"{f}: [{sec}] {k} must be 3 numbers")
            if "rpy" in doc[sec] and "rpy_deg" in doc[sec]:
                errs.append(f"{f}: [{sec}] both rpy and rpy_deg")
    if "gravity" in doc and not (len(doc["gravity"]) == 3 and all(num(e) for e in doc["gravity"])):
        errs.append(f"{f}: gravity must be 3 numbers")
    joints = doc.get("joint", [])
    if not joints:
        errs.append(f"{f}: no [[joint]] rows")
    for i, j in enumerate(joints, 1):
        where = f"{f}: row {i}"
        for k in j:
            if k not in JOINT_KEYS:
                errs.append(f"{where}: unknown key '{k}'")
        if j.get("type") not in ("R", "P"):
            errs.append(f"{where}: type must be R or P")
        if ("theta" in j) + ("theta_deg" in j) != 1:
            errs.append(f"{where}: exactly one of theta/theta_deg required")
        for a, b in (("alpha", "alpha_deg"), ("lower", "lower_deg"), ("upper", "upper_deg")):
            if a in j and b in j:
                errs.append(f"{where}: both {a} and {b}")
        if j.get("type") == "P" and ("lower_deg" in j or "upper_deg" in j):
            errs.append(f"{where}: lower_deg/upper_deg are for revolute joints only")
        for k in ("theta", "theta_deg", "d", "a", "alpha", "alpha_deg", "lower", "lower_deg", "upper",
                  "upper_deg", "velocity", "effort", "mass", "motor_inertia", "gear_ratio"):
            if k in j and not num(j[k]):
                errs.append(f"{where}: {k} must be a number")
        if "com" in j and not (len(j["com"]) == 3 and all(num(e) for e in j["com"])):
            errs.append(f"{where}: com must be 3 numbers")
        if "inertia" in j and not (len(j["inertia"]) == 6 and all(num(e) for e in j["inertia"])):
            errs.append(f"{where}: inertia must be 6 numbers")
        has_lo = "lower" in j or "lower_deg" in j
        has_hi = "upper" in j or "upper_deg" in j
        cont = j.get("continuous", False)
        if cont and j.get("type") != "R":
            errs.append(f"{where}: continuous only for revolute joints")
        if has_lo != has_hi:
            errs.append(f"{where}: give both lower and upper")
        if not has_lo and not cont:
            errs.append(f"{where}: no limits and not continuous")
        if has_lo and has_hi:
            lo = j["lower"] if "lower" in j else math.radians(j["lower_deg"])
            hi = j["upper"] if "upper" in j else math.radians(j["upper_deg"])
            if lo > hi:
                errs.append(f"{where}: lower > upper")
        if j.get("mass", 0.0) < 0:
            errs.append(f"{where}: negative mass")
    return errs


class DHModel:
    def __init__(self, path):
        self.path = path
        with open(path, "rb") as fh:
            self.doc = tomllib.load(fh)
        d = self.doc
        self.name = d["name"]
        self.modified = d["convention"] == "modified"
        self.base = self._frame(d.get("base"))
        self.tool = self._frame(d.get("tool"))
        self.has_tool = "tool" in d
        self.rows = []
        for j in d["joint"]:
            g = lambda k, kd: j[k] if k in j else math.radians(j[kd]) if kd in j else 0.0
            row = dict(type=j["type"], theta=g("theta", "theta_deg"), d=j.get("d", 0.0),
                       a=j.get("a", 0.0), alpha=g("alpha", "alpha_deg"),
                       mass=j.get("mass", 0.0), com=np.array(j.get("com", [0.0, 0.0, 0.0]), float),
                       inertia=inertia_matrix(j.get("inertia", [0.0] * 6)),
                       Jm=j.get("motor_inertia", 0.0), G=j.get("gear_ratio", 1.0),
                       continuous=j.get("continuous", False))
            if "lower" in j or "lower_deg" in j:
                row["lower"] = g("lower", "lower_deg")
                row["upper"] = g("upper", "upper_deg")
            else:
                row["lower"], row["upper"] = -math.pi, math.pi
            self.rows.append(row)
        self.n = len(self.rows)

    @staticmethod
    def _frame(sec):
        if not sec:
            return np.eye(4)
        xyz = sec.get("xyz", [0.0, 0.0, 0.0])
        rpy = sec["rpy"] if "rpy" in sec else [math.radians(v) for v in sec.get("rpy_deg", [0, 0, 0])]
        return hom(rpy_to_R(*rpy), xyz)

    def link_matrix(self, i, q):
        r = self.rows[i]
        th, d = r["theta"], r["d"]
        if r["type"] == "R":
            th = th + q
        else:
            d = d + q
        if self.modified:
            return Rx4(r["alpha"]) @ Tx4(r["a"]) @ Rz4(th) @ Tz4(d)
        return Rz4(th) @ Tz4(d) @ Tx4(r["a"]) @ Rx4(r["alpha"])

    def frames(self, q):
        """World transforms of DH frames 0..n (list of n+1) and of the tool."""
        T = self.base.copy()
        out = [T]
        for i in range(self.n):
            T = T @ self.link_matrix(i, q[i])
            out.append(T)
        return out, T @ self.tool

    def bodies(self, q):
        """Generic description for the Jacobian dynamics: per moving body (one per joint) the world
        joint axis/origin of the joint that moves it, its mass, world COM and world inertia."""
        F, _ = self.frames(q)
        joints, bodies = [], []
        for i, r in enumerate(self.rows):
            if self.modified:  # joint i axis is z of frame i
                Tj = F[i + 1]
            else:  # standard: joint i acts about/along z_{i-1}
                Tj = F[i]
            joints.append(dict(kind=r["type"], axis=Tj[:3, 2].copy(), origin=Tj[:3, 3].copy()))
            Tl = F[i + 1]
            R = Tl[:3, :3]
            bodies.append(dict(joint=i, m=r["mass"], c=Tl[:3, :3] @ r["com"] + Tl[:3, 3],
                               I=R @ r["inertia"] @ R.T))
        return joints, bodies

    def sample(self, rng):
        return np.array([rng.uniform(r["lower"], r["upper"]) for r in self.rows])


# --------------------------------------------------------------------------------------------
# URDF parser and kinematic tree
# --------------------------------------------------------------------------------------------
def _vec(s, default):
    return np.array([float(v) for v in s.split()]) if s is not None else np.array(default, float)


class URDFModel:
    def __init__(self, path):
        self.path = path
        tree = ET.parse(path)
        root = tree.getroot()
        assert root.tag == "robot"
        self.name = root.get("name")
        self.links = {}
        for l in root.findall("link"):
            inert = l.find("inertial")
            if inert is not None:
                o = inert.find("origin")
                xyz = _vec(o.get("xyz") if o is not None else None, [0, 0, 0])
                rpy = _vec(o.get("rpy") if o is not None else None, [0, 0, 0])
                m = float(inert.find("mass").get("value"))
                ie = inert.find("inertia")
                Iv = [float(ie.get(k, "0")) for k in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")]
                self.links[l.get("name")] = dict(m=m, T=hom(rpy_to_R(*rpy), xyz), I=inertia_matrix(Iv))
            else:
                self.links[l.get("name")] = None
        self.joints = {}
        self.child_of = {}
        for j in root.findall("joint"):
            o = j.find("origin")
            xyz = _vec(o.get("xyz") if o is not None else None, [0, 0, 0])
            rpy = _vec(o.get("rpy") if o is not None else None, [0, 0, 0])
            ax = j.find("axis")
            lim = j.find("limit")
            mim = j.find("mimic")
            jd = dict(name=j.get("name"), type=j.get("type"), parent=j.find("parent").get("link"),
                      child=j.find("child").get("link"), T=hom(rpy_to_R(*rpy), xyz),
                      axis=_vec(ax.get("xyz") if ax is not None else None, [1, 0, 0]),
                      lower=float(lim.get("lower", 0)) if lim is not None else None,
                      upper=float(lim.get("upper", 0)) if lim is not None else None,
                      mimic=None)
            if mim is not None:
                jd["mimic"] = (mim.get("joint"), float(mim.get("multiplier", 1)), float(mim.get("offset", 0)))
            self.joints[jd["name"]] = jd
            self.child_of[jd["child"]] = jd
        roots = [l for l in self.links if l not in self.child_of]
        self.problems = []
        if len(roots) != 1:
            self.problems.append(f"{len(roots)} root links: {roots}")
        self.root = roots[0]
        for j in self.joints.values():
            if j["parent"] not in self.links or j["child"] not in self.links:
                self.problems.append(f"joint {j['name']} references a missing link")
            if j["type"] in ("revolute", "prismatic") and (j["lower"] is None or j["lower"] > j["upper"]):
                self.problems.append(f"joint {j['name']} has bad limits")
            if j["mimic"] and j["mimic"][0] not in self.joints:
                self.problems.append(f"joint {j['name']} mimics a missing joint")
        # independent actuated joints in tree (depth-first) order
        self.order = []
        self._dfs(self.root)
        self.active = [n for n in self.order if self.joints[n]["type"] in ("revolute", "continuous", "prismatic")
                       and not self.joints[n]["mimic"]]

    def _dfs(self, link):
        for j in self.joints.values():
            if j["parent"] == link:
                self.order.append(j["name"])
                self._dfs(j["child"])

    def joint_value(self, name, qd):
        j = self.joints[name]
        if j["mimic"]:
            src, mul, off = j["mimic"]
            return mul * qd.get(src, 0.0) + off
        return qd.get(name, 0.0)

    def fk(self, qd, base=np.eye(4)):
        """World transform of every link; also per-joint world axis/origin (after the joint origin)."""
        X = {self.root: base.copy()}
        jinfo = {}
        for n in self.order:
            j = self.joints[n]
            Tp = X[j["parent"]] @ j["T"]
            qv = self.joint_value(n, qd)
            if j["type"] in ("revolute", "continuous"):
                M = hom(axis_angle(j["axis"], qv))
            elif j["type"] == "prismatic":
                M = hom(p=qv * j["axis"] / np.linalg.norm(j["axis"]))
            else:
                M = np.eye(4)
            X[j["child"]] = Tp @ M
            if j["type"] != "fixed":
                jinfo[n] = dict(axis=Tp[:3, :3] @ (j["axis"] / np.linalg.norm(j["axis"])), origin=Tp[:3, 3].copy(),
                                kind="R" if j["type"] in ("revolute", "continuous") else "P")
        return X, jinfo

    def moving_joint_of(self, link):
        """Nearest non-fixed joint above `link` (None if the link is welded to the root)."""
        while link in self.child_of:
            j = self.child_of[link]
            if j["type"] != "fixed":
                return j["name"]
            link = j["parent"]
        return None

    def bodies(self, qd, active=None):
        active = active or self.active
        X, jinfo = self.fk(qd)
        joints = []
        idx = {}
        for n in active:
            idx[n] = len(joints)
            joints.append(jinfo[n])
        bodies = []
        for ln, inert in self.links.items():
            if inert is None:
                continue
            Tb = X[ln] @ inert["T"]
            mj = self.moving_joint_of(ln)
            if mj is None:
                continue
            src = self.joints[mj]
            # a mimic joint moves with its master: express as the master index with its multiplier
            bodies.append(dict(link=ln, joint_name=mj, m=inert["m"], c=Tb[:3, 3].copy(),
                               I=Tb[:3, :3] @ inert["I"] @ Tb[:3, :3].T))
        return X, jinfo, joints, idx, bodies

    def sample(self, rng):
        qd = {}
        for n in self.active:
            j = self.joints[n]
            if j["type"] == "continuous":
                qd[n] = rng.uniform(-math.pi, math.pi)
            else:
                qd[n] = rng.uniform(j["lower"], j["upper"])
        return qd


# --------------------------------------------------------------------------------------------
# Jacobian dynamics: M(q) = sum m Jv^T Jv + Jw^T I Jw,  g(q) = -sum m Jv^T gvec
# --------------------------------------------------------------------------------------------
def ancestors_dh(model: DHModel, body_joint):
    return list(range(body_joint + 1))


def mass_and_gravity(joints, bodies, supports, gvec):
    """joints: list of dict(axis, origin, kind); bodies: list of dict(m, c, I);
    supports[b]: list of (joint index, multiplier) moving body b."""
    n = len(joints)
    M = np.zeros((n, n))
    g = np.zeros(n)
    for b, body in enumerate(bodies):
        Jv = np.zeros((3, n))
        Jw = np.zeros((3, n))
        for (k, mul) in supports[b]:
            jt = joints[k]
            if jt["kind"] == "R":
                Jv[:, k] += mul * np.cross(jt["axis"], body["c"] - jt["origin"])
                Jw[:, k] += mul * jt["axis"]
            else:
                Jv[:, k] += mul * jt["axis"]
        M += body["m"] * Jv.T @ Jv + Jw.T @ body["I"] @ Jw
        g += -body["m"] * Jv.T @ gvec
    return M, g


def dh_dynamics(model: DHModel, q, gvec=np.array([0, 0, -9.81]), with_motors=False):
    joints, bodies = model.bodies(q)
    supports = [[(k, 1.0) for k in range(b["joint"] + 1)] for b in bodies]
    M, g = mass_and_gravity(joints, bodies, supports, gvec)
    if with_motors:
        M += np.diag([r["Jm"] * r["G"] ** 2 for r in model.rows])
    return M, g


def urdf_dynamics(model: URDFModel, qd, gvec=np.array([0, 0, -9.81])):
    X, jinfo, joints, idx, bodies = model.bodies(qd)
    # joints of the tree are all active ones; a mimic joint contributes to its master's column
    supports = []
    for b in bodies:
        sup = []
        link = b["link"]
        while link in model.child_of:
            j = model.child_of[link]
            if j["type"] != "fixed":
                if j["mimic"]:
                    src, mul, _ = j["mimic"]
                    # the mimic joint's own axis, scaled, in the master's column
                    sup.append(("mimic", j["name"], idx[src], mul))
                else:
                    sup.append(("own", j["name"], idx[j["name"]], 1.0))
            link = j["parent"]
        supports.append(sup)
    n = len(joints)
    M = np.zeros((n, n))
    g = np.zeros(n)
    for b, body in enumerate(bodies):
        Jv = np.zeros((3, n))
        Jw = np.zeros((3, n))
        for (_, jname, k, mul) in supports[b]:
            jt = jinfo[jname]
            if jt["kind"] == "R":
                Jv[:, k] += mul * np.cross(jt["axis"], body["c"] - jt["origin"])
                Jw[:, k] += mul * jt["axis"]
            else:
                Jv[:, k] += mul * jt["axis"]
        M += body["m"] * Jv.T @ Jv + Jw.T @ body["I"] @ Jw
        g += -body["m"] * Jv.T @ gvec
    return M, g


# --------------------------------------------------------------------------------------------
# inertia plausibility
# --------------------------------------------------------------------------------------------
def inertia_report(label, m, I, known=None):
    """PSD, triangle inequality, PD (strict).  known: explanation string for a documented
    published-data exception (reported as KNOWN instead of FAIL)."""
    I = 0.5 * (I + I.T)
    if m == 0 and not np.any(I):
        return
    ev = np.linalg.eigvalsh(I)
    scale = max(1e-300, float(np.max(np.abs(ev))))
    psd = ev[0] >= -1e-12 * scale
    tri = (ev[0] + ev[1] >= ev[2] - 1e-12 * scale)
    pd = ev[0] > 1e-12 * scale
    massok = (m > 0) or not np.any(I)
    ok = psd and tri and massok
    detail = f"m={m:g} eig=({ev[0]:.6g}, {ev[1]:.6g}, {ev[2]:.6g})" + ("" if pd else " [semi-definite: thin rod/lamina]")
    if not massok:
        detail += " [zero mass with non-zero inertia]"
    if not tri:
        detail += " [triangle inequality violated]"
    if ok:
        report("PASS", f"inertia {label}", detail)
    elif known:
        report("KNOWN", f"inertia {label}", detail + " -- " + known)
    else:
        report("FAIL", f"inertia {label}", detail)


# --------------------------------------------------------------------------------------------
# the checks
# --------------------------------------------------------------------------------------------
def load_dh(name):
    path = os.path.join(ROBOTS, name)
    with open(path, "rb") as fh:
        doc = tomllib.load(fh)
    errs = validate_toml(path, doc)
    check(not errs, f"schema {name}", "; ".join(errs) if errs else "keys/limits/rows conform to docs/dh-format.md")
    return DHModel(path)


def load_urdf(name):
    m = URDFModel(os.path.join(ROBOTS, name))
    check(not m.problems, f"urdf structure {name}",
          "; ".join(m.problems) if m.problems else
          f"root {m.root}, {len(m.links)} links, {len(m.joints)} joints, {len(m.active)} actuated: {', '.join(m.active)}")
    return m


def compare_world_inertias(tag, dh, ur, link_map, rng, samples, only_links=None):
    """Same mass, world COM and world inertia per moving body (URDF bodies lumped per DH link).
    only_links: restrict the URDF bodies (e.g. the Panda arm without its hand)."""
    worst = 0.0
    for _ in range(samples):
        q = dh.sample(rng)
        qd = {n: q[i] for i, n in enumerate(link_map)}
        _, bodies_dh = dh.bodies(q)
        X, jinfo, joints, idx, bodies_u = ur.bodies(qd)
        for i, jn in enumerate(link_map):
            grp = [b for b in bodies_u if b["joint_name"] == jn and (only_links is None or b["link"] in only_links)]
            mu = sum(b["m"] for b in grp)
            cu = sum(b["m"] * b["c"] for b in grp) / mu
            Iu = np.zeros((3, 3))
            for b in grp:  # parallel-axis to the group COM
                r = b["c"] - cu
                Iu += b["I"] + b["m"] * (np.dot(r, r) * np.eye(3) - np.outer(r, r))
            bd = bodies_dh[i]
            worst = max(worst, abs(mu - bd["m"]), float(np.max(np.abs(cu - bd["c"]))),
                        float(np.max(np.abs(Iu - bd["I"]))))
    return check(worst <= TOL, f"{tag} dynamics DH == URDF (mass, world COM, world inertia per link)",
                 f"max abs diff {worst:.3e} over {samples} random q")


def check_ur5(rng, samples, pin, rtb=None):
    dh = load_dh("ur5_dh.toml")
    ur = load_urdf("ur5.urdf")
    yourdfpy_validate("ur5.urdf")
    names = [r for r in ur.active]
    check(names == ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint",
                    "wrist_2_joint", "wrist_3_joint"], "ur5 joint order", ", ".join(names))
    dn = [j.get("name") for j in dh.doc["joint"]]
    check(dn == names, "ur5 DH joint names == URDF joint names")
    # limits/velocity/effort identical
    same = True
    for i, n in enumerate(names):
        j = ur.joints[n]
        r = dh.rows[i]
        lim = ET.parse(ur.path).getroot().find(f"joint[@name='{n}']/limit")
        same &= (j["lower"] == r["lower"] and j["upper"] == r["upper"]
                 and float(lim.get("velocity")) == dh.doc["joint"][i]["velocity"]
                 and float(lim.get("effort")) == dh.doc["joint"][i]["effort"])
    check(same, "ur5 limits/velocity/effort DH == URDF")
    ep = er = 0.0
    ep6 = er6 = 0.0
    for _ in range(samples):
        q = dh.sample(rng)
        F, tool = dh.frames(q)
        X, _ = ur.fk({n: q[i] for i, n in enumerate(names)})
        a, b = pose_err(tool, X["tool0"])
        ep, er = max(ep, a), max(er, b)
        a, b = pose_err(F[0], X["base"])
        c, d = pose_err(F[6], X["wrist_3_link"])
        ep6, er6 = max(ep6, a, c), max(er6, b, d)
    check(max(ep, er) <= TOL, "ur5 DH tool == URDF tool0",
          f"{samples} random q: max |dp| {ep:.3e} m, max |dR| {er:.3e}")
    check(max(ep6, er6) <= TOL, "ur5 DH frame 0 == URDF 'base', DH frame 6 == wrist_3_link",
          f"max |dp| {ep6:.3e}, max |dR| {er6:.3e}")
    X0, _ = ur.fk({n: 0.0 for n in names})
    T = X0["tool0"]
    # by hand: in DH frame 0 the zero pose is (a2 + a3, -(d4 + d6), d1 - d5) with R0_6 = [[1,0,0],[0,0,-1],[0,1,0]];
    # base_link = Rz(pi) * frame 0 flips x and y
    p_ref = np.array([0.425 + 0.39225, 0.10915 + 0.0823, 0.089159 - 0.09465])
    R_ref = np.array([[-1.0, 0, 0], [0, 0, 1.0], [0, 1.0, 0]])
    check(np.allclose(T[:3, 3], p_ref, atol=1e-15) and np.allclose(T[:3, :3], R_ref, atol=1e-15),
          "ur5 tool0 at q = 0 == hand-derived pose",
          f"p = {np.round(T[:3, 3], 12).tolist()}, R = {np.round(T[:3, :3], 12).tolist()}")
    compare_world_inertias("ur5", dh, ur, names, rng, min(samples, 200))
    # mass matrix & gravity, own Jacobian code, DH vs URDF
    worst = 0.0
    for _ in range(min(samples, 200)):
        q = dh.sample(rng)
        Md, gd = dh_dynamics(dh, q)
        Mu, gu = urdf_dynamics(ur, {n: q[i] for i, n in enumerate(names)})
        worst = max(worst, float(np.max(np.abs(Md - Mu))), float(np.max(np.abs(gd - gu))))
    check(worst <= 1e-12, "ur5 M(q), g(q) DH == URDF (own Jacobian code)", f"max abs diff {worst:.3e}")
    for i, r in enumerate(dh.rows):
        inertia_report(f"ur5_dh link{i + 1}", r["mass"], r["inertia"])
    if rtb:
        from spatialmath import SE3
        robot = rtb.models.DH.UR5()
        robot.links[0].d = 0.089159  # RTB's UR5.py has d1 = 0.089459; UR/ur_description publish 0.089159
        robot.base, robot.tool = SE3(), SE3()
        w = 0.0
        for _ in range(50):
            q = dh.sample(rng)
            F, _ = dh.frames(q)
            w = max(w, *pose_err(np.linalg.inv(dh.base) @ F[6], robot.fkine(q).A))
        check(w <= TOL, "ur5 DH frame 6 (in DH frame 0) == RTB DH.UR5 with d1 = 0.089159", f"50 q: max diff {w:.3e}")
    if pin:
        pin_compare("ur5", ur, ["tool0", "wrist_3_link", "base", "flange"], rng, samples, pin)


def check_panda(rng, samples, pin, rtb):
    dh = load_dh("panda_mdh.toml")
    ur = load_urdf("panda.urdf")
    yourdfpy_validate("panda.urdf")
    arm = [f"panda_joint{i}" for i in range(1, 8)]
    check(ur.active == arm + ["panda_finger_joint1"], "panda actuated joints",
          ", ".join(ur.active) + " (panda_finger_joint2 mimics panda_finger_joint1)")
    j2 = ur.joints["panda_finger_joint2"]
    check(j2["mimic"] == ("panda_finger_joint1", 1.0, 0.0), "panda finger mimic", str(j2["mimic"]))
    same = all(ur.joints[n]["lower"] == dh.rows[i]["lower"] and ur.joints[n]["upper"] == dh.rows[i]["upper"]
               for i, n in enumerate(arm))
    check(same, "panda limits MDH == URDF")
    ep = er = epl = erl = 0.0
    for _ in range(samples):
        q = dh.sample(rng)
        F, tool = dh.frames(q)
        qd = {n: q[i] for i, n in enumerate(arm)}
        qd["panda_finger_joint1"] = rng.uniform(0, 0.04)
        X, _ = ur.fk(qd)
        a, b = pose_err(tool, X["panda_link8"])
        ep, er = max(ep, a), max(er, b)
        for i in range(1, 8):
            a, b = pose_err(F[i], X[f"panda_link{i}"])
            epl, erl = max(epl, a), max(erl, b)
    check(max(ep, er) <= TOL, "panda MDH tool == URDF panda_link8", f"{samples} random q: max |dp| {ep:.3e} m, max |dR| {er:.3e}")
    check(max(epl, erl) <= TOL, "panda MDH frame i == URDF panda_link<i>", f"max |dp| {epl:.3e}, max |dR| {erl:.3e}")
    compare_world_inertias("panda arm (links 1-7, hand excluded)", dh, ur, arm, rng, min(samples, 200),
                           only_links={f"panda_link{i}" for i in range(1, 8)})
    for i, r in enumerate(dh.rows):
        inertia_report(f"panda_mdh link{i + 1}", r["mass"], r["inertia"])
    for ln, inert in ur.links.items():
        if inert is not None:
            inertia_report(f"panda.urdf {ln}", inert["m"], inert["I"])
    if rtb:
        robot = rtb.models.DH.Panda()
        from spatialmath import SE3
        robot.tool = SE3()
        worst = 0.0
        for _ in range(20):
            q = dh.sample(rng)
            _, tool = dh.frames(q)
            worst = max(worst, *pose_err(tool, robot.fkine(q).A))
        check(worst <= TOL, "panda MDH tool == RTB DH.Panda flange (tool offset removed)", f"20 q: max diff {worst:.3e}")
    if pin:
        pin_compare("panda", ur, ["panda_link8", "panda_hand_tcp", "panda_leftfinger", "panda_rightfinger"],
                    rng, samples, pin)


def check_iiwa(rng, samples, pin):
    ur = load_urdf("iiwa14.urdf")
    yourdfpy_validate("iiwa14.urdf")
    check(ur.root == "iiwa_link_0" and "iiwa_link_ee" in ur.links, "iiwa14 root iiwa_link_0, tip iiwa_link_ee")
    X, _ = ur.fk({n: 0.0 for n in ur.active})
    z = X["iiwa_link_ee"][:3, 3]
    check(np.allclose(z, [0, 0, 1.306], atol=1e-12), "iiwa14 flange height at q = 0",
          f"{z.tolist()} (datasheet 0.36 + 0.42 + 0.40 + 0.126 = 1.306 m)")
    jz = [X[f"iiwa_link_{i}"][:3, 3][2] for i in (2, 4, 6)]
    check(np.allclose(jz, [0.36, 0.78, 1.18], atol=1e-12), "iiwa14 J2/J4/J6 axis heights", str(np.round(jz, 12).tolist()))
    for ln, inert in ur.links.items():
        if inert is not None:
            inertia_report(f"iiwa14 {ln}", inert["m"], inert["I"])
    if pin:
        pin_compare("iiwa14", ur, ["iiwa_link_ee", "iiwa_link_ee_kuka", "iiwa_link_7"], rng, samples, pin)


def yourdfpy_validate(name):
    try:
        import yourdfpy
    except Exception:
        report("SKIP", f"yourdfpy validation {name}", "yourdfpy not installed")
        return
    r = yourdfpy.URDF.load(os.path.join(ROBOTS, name), load_meshes=False, build_collision_scene_graph=False,
                           load_collision_meshes=False)
    check(bool(r.validate()), f"{name} loads and validates with yourdfpy {yourdfpy.__version__ if hasattr(yourdfpy, '__version__') else ''}".rstrip(),
          f"actuated joints: {len(r.actuated_joint_names)}")


def pin_compare(tag, ur, frames, rng, samples, pin):
    """FK of named frames, mass matrix and gravity: own URDF code vs Pinocchio's URDF parser."""
    model = pin.buildModelFromUrdf(ur.path)
    data = model.createData()
    worst = 0.0
    worstM = 0.0
    for s in range(samples):
        qd = ur.sample(rng)
        q = pin.neutral(model)
        for jid in range(1, model.njoints):
            name = model.names[jid]
            v = ur.joint_value(name, qd)
            q[model.joints[jid].idx_q] = v
        pin.forwardKinematics(model, data, q)
        pin.updateFramePlacements(model, data)
        X, _ = ur.fk(qd)
        for fn in frames:
            fid = model.getFrameId(fn)
            Tp = data.oMf[fid].homogeneous
            worst = max(worst, *pose_err(Tp, X[fn]))
        if s < 100:
            Mp = pin.crba(model, data, q)
            Mp = np.triu(Mp) + np.triu(Mp, 1).T
            gp = pin.computeGeneralizedGravity(model, data, q)
            Mu, gu = urdf_dynamics(ur, qd)
            # pinocchio treats the mimic joint as independent: fold its column into the master
            cols = {}
            for jid in range(1, model.njoints):
                cols[model.names[jid]] = model.joints[jid].idx_v
            T = np.zeros((model.nv, len(ur.active)))
            for k, n in enumerate(ur.active):
                T[cols[n], k] = 1.0
            for n, j in ur.joints.items():
                if j["mimic"]:
                    T[cols[n], ur.active.index(j["mimic"][0])] = j["mimic"][1]
            worstM = max(worstM, float(np.max(np.abs(T.T @ Mp @ T - Mu))), float(np.max(np.abs(T.T @ gp - gu))))
    check(worst <= TOL, f"{tag} URDF FK == Pinocchio {pin.__version__}", f"frames {frames}, {samples} q: max diff {worst:.3e}")
    check(worstM <= 1e-10, f"{tag} URDF M(q), g(q) == Pinocchio crba/gravity", f"100 q: max diff {worstM:.3e}")


def check_textbook(rng, samples):
    # spherical RRP closed form
    m = load_dh("textbook_spherical_rrp.toml")
    check(m.rows[2]["type"] == "P" and m.rows[2]["lower"] > 0, "spherical_rrp: q3 = r prismatic, lower limit > 0",
          f"r in [{m.rows[2]['lower']}, {m.rows[2]['upper']}] m")
    worst = 0.0
    worst_ik = 0.0
    for _ in range(samples):
        q = m.sample(rng)
        _, tool = m.frames(q)
        g1, b2, r = q
        p = np.array([r * math.cos(g1) * math.cos(b2), r * math.sin(g1) * math.cos(b2), r * math.sin(b2)])
        worst = max(worst, float(np.max(np.abs(tool[:3, 3] - p))))
        x, y, z = tool[:3, 3]
        ik = np.array([math.atan2(y, x), math.atan2(z, math.hypot(x, y)), math.sqrt(x * x + y * y + z * z)])
        worst_ik = max(worst_ik, float(np.max(np.abs(ik - q))))
        # tool z axis along the arm
        worst = max(worst, float(np.max(np.abs(tool[:3, 2] - p / r))))
    check(worst <= TOL, "spherical_rrp tool == (r cg1 cb2, r sg1 cb2, r sb2), z_tool along the arm",
          f"{samples} random q: max diff {worst:.3e}")
    check(worst_ik <= 1e-12, "spherical_rrp closed-form inverse recovers q", f"max diff {worst_ik:.3e}")

    def closed(name, f):
        mm = load_dh(name)
        w = 0.0
        for _ in range(samples):
            q = mm.sample(rng)
            _, tool = mm.frames(q)
            w = max(w, float(np.max(np.abs(tool[:3, 3] - f(q)))))
        check(w <= TOL, f"{name} tool == closed form", f"{samples} random q: max diff {w:.3e}")
        for i, r in enumerate(mm.rows):
            inertia_report(f"{name} link{i + 1}", r["mass"], r["inertia"])
        return mm

    mc = closed("textbook_cartesian_ppp.toml", lambda q: np.array([q[0], q[1], 0.2 + q[2]]))
    _, tool = mc.frames(mc.sample(rng))
    check(np.allclose(tool[:3, :3], np.eye(3), atol=1e-15), "cartesian_ppp tool axes == world axes")
    closed("textbook_cylindrical_rpp.toml", lambda q: np.array([q[2] * math.cos(q[0]), q[2] * math.sin(q[0]), q[1]]))
    closed("textbook_scara_rrp.toml", lambda q: np.array([0.35 * math.cos(q[0]) + 0.25 * math.cos(q[0] + q[1]),
                                                          0.35 * math.sin(q[0]) + 0.25 * math.sin(q[0] + q[1]),
                                                          0.4 - q[2]]))

    def rrr(q):
        r = 0.45 * math.cos(q[1]) + 0.4 * math.cos(q[1] + q[2])
        return np.array([r * math.cos(q[0]), r * math.sin(q[0]), 0.5 + 0.45 * math.sin(q[1]) + 0.4 * math.sin(q[1] + q[2])])

    closed("textbook_articulated_rrr.toml", rrr)
    for i, r in enumerate(m.rows):
        inertia_report(f"textbook_spherical_rrp link{i + 1}", r["mass"], r["inertia"])

    # 5R Minimover
    m5 = load_dh("textbook_5r.toml")
    _, T = m5.frames(np.zeros(5))
    check(abs(m5.rows[1]["a"] - m5.rows[2]["a"]) == 0.0, "textbook_5r a2 == a3")
    check(np.allclose(T[:3, 2], [0, 0, -1], atol=1e-15), "textbook_5r alpha4 = -90 deg: gripper axis points down at q = 0",
          f"tool p = {np.round(T[:3, 3], 9).tolist()}, z = {np.round(T[:3, 2], 12).tolist()}")

    # planar 2R against the textbook closed forms (angles from +x, CCW in x-z, z up)
    p2 = load_dh("planar_2r.toml")
    l, m1, m2, gg = 0.5, 2.0, 1.0, 9.81
    wM = wg = wp = 0.0
    for _ in range(samples):
        q = np.array([rng.uniform(-math.pi, math.pi), rng.uniform(-math.pi, math.pi)])
        M, g = dh_dynamics(p2, q)
        c2 = math.cos(q[1])
        Mref = np.array([[m1 * l * l / 3 + m2 * l * l * (4 / 3 + c2), m2 * l * l * (1 / 3 + c2 / 2)],
                         [m2 * l * l * (1 / 3 + c2 / 2), m2 * l * l / 3]])
        gref = np.array([(m1 / 2 + m2) * gg * l * math.cos(q[0]) + m2 / 2 * gg * l * math.cos(q[0] + q[1]),
                         m2 / 2 * gg * l * math.cos(q[0] + q[1])])
        _, tool = p2.frames(q)
        pref = np.array([l * math.cos(q[0]) + l * math.cos(q[0] + q[1]), 0.0,
                         l * math.sin(q[0]) + l * math.sin(q[0] + q[1])])
        wM, wg, wp = max(wM, float(np.max(np.abs(M - Mref)))), max(wg, float(np.max(np.abs(g - gref)))), \
            max(wp, float(np.max(np.abs(tool[:3, 3] - pref))))
    check(wp <= TOL, "planar_2r tip == (l c1 + l c12, 0, l s1 + l s12) in world x-z", f"max diff {wp:.3e}")
    check(wM <= 1e-12, "planar_2r M(q) == textbook M11, M12, M22", f"max diff {wM:.3e}")
    check(wg <= 1e-12, "planar_2r g(q) == textbook g1, g2 (y up)", f"max diff {wg:.3e}")
    _, T = p2.frames(np.array([math.pi / 2, 0.0]))
    check(np.allclose(T[:3, 3], [0, 0, 1.0], atol=1e-15), "planar_2r q1 = pi/2 points straight up", str(np.round(T[:3, 3], 15).tolist()))
    for i, r in enumerate(p2.rows):
        inertia_report(f"planar_2r link{i + 1}", r["mass"], r["inertia"])


KNOWN = {
    ("puma560", 1): "published (Armstrong 1986 / Corke): m1 = 0, I1 = [0, 0.35, 0]; only Iyy enters tau1",
    ("puma560", 3): "published (Corke/Armstrong): I3 = [0.066, 0.086, 0.0125]",
    ("stanford", 5): "published (Corke mdl_stanford / Paul 1981): I5 = [0.003, 0.0004, 0]",
}


def check_classics(rng, samples, rtb):
    pu = load_dh("puma560.toml")
    st = load_dh("stanford.toml")
    co = load_dh("scara.toml")
    for mm, tag in ((pu, "puma560"), (st, "stanford")):
        for i, r in enumerate(mm.rows):
            inertia_report(f"{tag} link{i + 1}", r["mass"], r["inertia"], KNOWN.get((tag, i + 1)))
    if not rtb:
        report("SKIP", "Robotics Toolbox cross-checks", "roboticstoolbox-python not installed")
        return
    from spatialmath import SE3
    models = []
    p = rtb.models.DH.Puma560()
    models.append(("puma560", pu, p, "RTB DH.Puma560 (as is)"))
    s = rtb.models.DH.Stanford()
    s.links[2].a = 0.0     # MATLAB mdl_stanford: a3 = 0   (Python model: 0.0203)
    s.links[5].d = 0.263   # MATLAB mdl_stanford: d6 = 0.263 (Python model: 0)
    models.append(("stanford", st, s, "RTB DH.Stanford with a3 = 0, d6 = 0.263 (= MATLAB mdl_stanford)"))
    c = rtb.models.DH.Cobra600()
    models.append(("cobra600", co, c, "RTB DH.Cobra600 (as is)"))
    for tag, mm, robot, what in models:
        robot.tool = SE3()
        robot.base = SE3()
        w = 0.0
        for _ in range(50):
            q = mm.sample(rng)
            _, tool = mm.frames(q)
            w = max(w, *pose_err(tool, robot.fkine(q).A))
        check(w <= TOL, f"{tag} FK == {what}", f"50 random q: max diff {w:.3e}")
        lims_ok = np.allclose(np.array([[r["lower"], r["upper"]] for r in mm.rows]).T, robot.qlim, atol=1e-12) \
            if tag != "cobra600" else np.allclose(np.array([[r["lower"], r["upper"]] for r in mm.rows[:3]]).T, robot.qlim[:, :3], atol=1e-12)
        check(bool(lims_ok), f"{tag} joint limits == RTB qlim")
        if tag in ("puma560", "stanford"):
            wM = wg = 0.0
            for _ in range(50):
                q = mm.sample(rng)
                M, g = dh_dynamics(mm, q, with_motors=True)
                Mr = robot.inertia(q)
                gr = robot.gravload(q, gravity=[0, 0, -9.81])
                wM = max(wM, float(np.max(np.abs(M - Mr))))
                wg = max(wg, float(np.max(np.abs(g - gr))))
            check(wM <= 1e-9 and wg <= 1e-9, f"{tag} M(q) (incl. G^2 Jm) and g(q) == RTB inertia()/gravload()",
                  f"50 random q: max |dM| {wM:.3e}, max |dg| {wg:.3e}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--samples", type=int, default=1000)
    ap.add_argument("--seed", type=int, default=20240521)
    args = ap.parse_args()
    rng = np.random.default_rng(args.seed)
    try:
        import pinocchio as pin
    except Exception:  # pragma: no cover
        pin = None
        report("SKIP", "Pinocchio cross-checks", "pin not installed (pip install pin)")
    try:
        import warnings
        warnings.filterwarnings("ignore")
        import roboticstoolbox as rtb
    except Exception:  # pragma: no cover
        rtb = None
    print(f"check_models.py: seed {args.seed}, {args.samples} random samples per FK check, tolerance {TOL:g}")
    print(f"numpy {np.__version__}" + (f", pinocchio {pin.__version__}" if pin else "") +
          (f", roboticstoolbox {rtb.__version__}" if rtb else ""))
    print("== UR5 ==")
    check_ur5(rng, args.samples, pin, rtb)
    print("== Panda ==")
    check_panda(rng, args.samples, pin, rtb)
    print("== iiwa14 ==")
    check_iiwa(rng, args.samples, pin)
    print("== textbook models ==")
    check_textbook(rng, args.samples)
    print("== Puma560 / Stanford / Cobra600 ==")
    check_classics(rng, args.samples, rtb)
    # every robots/*.toml must have been schema-checked
    seen = {n for (_, n, _) in RESULTS if n.startswith("schema ")}
    for f in sorted(os.listdir(ROBOTS)):
        if f.endswith(".toml") and f"schema {f}" not in seen:
            path = os.path.join(ROBOTS, f)
            with open(path, "rb") as fh:
                errs = validate_toml(path, tomllib.load(fh))
            check(not errs, f"schema {f}", "; ".join(errs))
    n = {s: sum(1 for r in RESULTS if r[0] == s) for s in ("PASS", "FAIL", "KNOWN", "SKIP", "INFO")}
    print(f"== summary: {n['PASS']} passed, {n['FAIL']} failed, {n['KNOWN']} known published-data exceptions, "
          f"{n['SKIP']} skipped ==")
    return 1 if n["FAIL"] else 0


if __name__ == "__main__":
    sys.exit(main())
