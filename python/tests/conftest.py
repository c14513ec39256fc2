"""Shared paths and the armsim <-> Pinocchio coordinate mapping for the tests."""

from __future__ import annotations

import os
import sysconfig
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
ROBOTS = ROOT / "robots"


def erd_robots() -> Path:
    """The robots directory of PyPI example-robot-data (a cmeel prefix)."""
    return Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix/share/example-robot-data/robots"


class PinMap:
    """Maps armsim coordinates (one per independent joint, continuous = an angle) to
    Pinocchio's q (continuous joints: cos, sin) and v, and back."""

    def __init__(self, am_model, pin_model):
        self.idx_q, self.idx_v, self.two = [], [], []
        for name in am_model.joint_names:
            jid = pin_model.getJointId(name)
            assert jid < pin_model.njoints, f"pin has no joint {name}"
            j = pin_model.joints[jid]
            assert j.nv == 1
            self.idx_q.append(j.idx_q)
            self.idx_v.append(j.idx_v)
            self.two.append(j.nq == 2)
        self.nq, self.nv = pin_model.nq, pin_model.nv
        assert self.nv == am_model.nv, "every pin coordinate is an armsim coordinate"

    def q(self, q):
        out = np.zeros(self.nq)
        for k, x in enumerate(q):
            if self.two[k]:
                out[self.idx_q[k]:self.idx_q[k] + 2] = (np.cos(x), np.sin(x))
            else:
                out[self.idx_q[k]] = x
        return out

    def v(self, v):
        out = np.zeros(self.nv)
        out[self.idx_v] = v
        return out

    def from_v(self, x):
        """A pin nv-vector (or the last axis of a matrix) in armsim's order."""
        return np.asarray(x)[..., self.idx_v]

    def from_vv(self, m):
        """A pin nv×nv matrix in armsim's order."""
        m = np.asarray(m)
        return m[np.ix_(self.idx_v, self.idx_v)]


def random_q(model, rng):
    lo, hi = model.lower_limits, model.upper_limits
    lo = np.where(np.isfinite(lo), lo, -np.pi)
    hi = np.where(np.isfinite(hi), hi, np.pi)
    return rng.uniform(lo, hi)


def assert_close(got, want, what, tol=1e-9):
    """|got - want| <= tol * max(1, max|want|) elementwise."""
    got, want = np.asarray(got), np.asarray(want)
    scale = max(1.0, float(np.max(np.abs(want)))) if want.size else 1.0
    err = float(np.max(np.abs(got - want))) if want.size else 0.0
    assert err <= tol * scale, f"{what}: max |armsim - pin| = {err:.3e} (scale {scale:.3e})"


@pytest.fixture(scope="session")
def rng():
    return np.random.default_rng(17)
