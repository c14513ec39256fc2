"""Joint order between armsim and Pinocchio: ``from_pinocchio_order`` and
``to_pinocchio_order`` move a configuration, velocity, acceleration or torque vector (or
an ``(N, n)`` batch of them) between the two libraries' coordinate orders, matching
joints by name.

armsim orders coordinates depth-first with children in file order (``model.joint_names``);
Pinocchio's URDF parser visits children in its own order, so on many trees (quadrupeds,
humanoids, dual arms) the same ``q`` means different things to the two libraries while
having the right length.

The Pinocchio model is duck-typed (``.names``, ``.joints[i].idx_q / .nq / .idx_v / .nv``,
``.nq``, ``.nv``): armsim never imports pinocchio. Supported Pinocchio joints are the
one-coordinate ones (revolute, prismatic: ``nq = nv = 1``) and continuous joints
(``nq = 2``: ``cos θ, sin θ``; ``nv = 1``), whose angle is converted to and from
``(cos, sin)`` in a configuration. Mimic joints of a ``mimic=True`` Pinocchio model
(``nq = nv = 0``) are skipped, as armsim gives them no coordinate either (unless loaded
with ``ignore_mimic=True``). Other joints are refused: a free-flyer (``nq = 7``: position
and quaternion, ``nv = 6``: a body-frame twist), a spherical or planar joint; armsim models
a URDF floating or planar joint as one-axis joints (``J_x``, …, ``J_yaw`` …) whose
velocities are Euler-angle rates, which no reordering maps onto Pinocchio's twist.
"""

from __future__ import annotations

from typing import Any, List, NamedTuple, Optional

import numpy as _np

from ._armsim import ArmsimError

__all__ = ["from_pinocchio_order", "to_pinocchio_order"]


class _Coord(NamedTuple):
    """One armsim coordinate's place in Pinocchio's vectors."""
    idx_q: int
    idx_v: int
    continuous: bool  # pin nq = 2 (cos, sin), nv = 1


class _Map(NamedTuple):
    coords: List[_Coord]
    pin_nq: int
    pin_nv: int


def _pin_joints(pin_model: Any) -> dict:
    """Pinocchio's joints by name (the universe excluded), each checked to be one
    armsim can map."""
    try:
        names = list(pin_model.names)
        joints = pin_model.joints
    except AttributeError as e:
        raise ArmsimError(
            f"pin_model: expected a pinocchio.Model (with .names and .joints), got "
            f"{type(pin_model).__name__}") from e
    out = {}
    for i in range(1, len(names)):
        out[names[i]] = joints[i]
    return out


def _check_pin_joint(name: str, j: Any) -> Optional[bool]:
    """Whether pin joint `name` is continuous (``True``), one coordinate (``False``) or a
    mimic joint without coordinates (``None``); a joint armsim has no counterpart of raises."""
    nq, nv = int(j.nq), int(j.nv)
    if nq == 0 and nv == 0:
        return None
    if nq == 1 and nv == 1:
        return False
    if nq == 2 and nv == 1:
        return True
    kind = j.shortname() if hasattr(j, "shortname") else "joint"
    what = {7: "a free-flyer (q: position + quaternion, v: a body-frame twist)",
            4: "a spherical joint (q: a quaternion) or a planar joint (q: x, y, cos, sin)"}
    raise ArmsimError(
        f"pin_model: joint '{name}' ({kind}, nq={nq}, nv={nv}) is "
        f"{what.get(nq, 'not a one-coordinate joint')}; only one-coordinate joints "
        "(nq = nv = 1) and continuous joints (nq = 2: cos, sin; nv = 1) convert. armsim "
        "models a URDF floating or planar joint as one-axis joints (J_x, J_y, ..., J_yaw) "
        "whose velocities are Euler-angle rates: build the Pinocchio model without a "
        "root joint, or convert the base coordinates yourself")


def _mapping(model: Any, pin_model: Any) -> _Map:
    """Where each armsim coordinate sits in Pinocchio's q and v; every name checked both
    ways."""
    pin = _pin_joints(pin_model)
    kinds = {name: _check_pin_joint(name, j) for name, j in pin.items()}
    ours = list(model.joint_names)
    coords = []
    for name in ours:
        if name not in pin:
            raise ArmsimError(
                f"joint '{name}' of armsim's model '{model.name}' is not in pin_model "
                f"(its joints: {', '.join(n for n in pin if kinds[n] is not None)})")
        if kinds[name] is None:
            raise ArmsimError(
                f"joint '{name}' is a mimic joint in pin_model (no coordinate) but a "
                "coordinate in armsim's model: load both the same way (armsim's "
                "ignore_mimic=True matches pin's default mimic=False)")
        j = pin[name]
        coords.append(_Coord(int(j.idx_q), int(j.idx_v), kinds[name]))
    known = set(ours)
    for name, kind in kinds.items():
        if kind is not None and name not in known:
            raise ArmsimError(
                f"joint '{name}' of pin_model has no coordinate in armsim's model "
                f"'{model.name}' (a mimic joint there? load it with ignore_mimic=True, as "
                "pin's parser does by default; or a different URDF)")
    return _Map(coords, int(pin_model.nq), int(pin_model.nv))


def _kind_of(kind: Optional[str], n: int, mp: _Map, what: str, to_pin: bool) -> str:
    """"q" or "v" for a vector whose last axis has `n` values."""
    if kind not in (None, "q", "v"):
        raise ArmsimError(f"kind: expected 'q', 'v' or None, got {kind!r}")
    if mp.pin_nq == mp.pin_nv:
        return kind or "v"  # the same map for both
    if to_pin:
        if kind is None:
            raise ArmsimError(
                f"kind: pin_model has continuous joints (nq={mp.pin_nq}, nv={mp.pin_nv}): "
                "say kind='q' for a configuration (angles become cos, sin) or kind='v' "
                "for a velocity, acceleration or torque")
        return kind
    if kind is None:
        if n == mp.pin_nq:
            return "q"
        if n == mp.pin_nv:
            return "v"
        raise ArmsimError(
            f"{what}: {n} values, but pin_model has nq={mp.pin_nq} (configuration) and "
            f"nv={mp.pin_nv} (velocity)")
    return kind


def _as_rows(x: Any, what: str) -> _np.ndarray:
    a = _np.asarray(x, dtype=float)
    if a.ndim not in (1, 2):
        raise ArmsimError(
            f"{what}: expected a vector or an (N, n) batch, got shape {a.shape}")
    return a


def from_pinocchio_order(model: Any, pin_model: Any, x: Any,
                         kind: Optional[str] = None) -> _np.ndarray:
    """``x`` in Pinocchio's order (a configuration of length ``pin_model.nq``, or a
    velocity / acceleration / torque of length ``pin_model.nv``; or an ``(N, n)`` batch)
    as armsim's ``(model.nv,)`` (or ``(N, model.nv)``) in ``model.joint_names`` order.

    ``kind`` ('q' or 'v') is inferred from the length when None. A continuous joint's
    ``(cos, sin)`` becomes its angle (``atan2``). Raises ``ArmsimError`` (a ``ValueError``)
    naming the joint when a name is missing on either side or a Pinocchio joint has no
    armsim counterpart (free-flyer, spherical, planar), and for a wrong length."""
    mp = _mapping(model, pin_model)
    a = _as_rows(x, "x")
    n = a.shape[-1]
    k = _kind_of(kind, n, mp, "x", to_pin=False)
    want = mp.pin_nq if k == "q" else mp.pin_nv
    if n != want:
        raise ArmsimError(f"x: {n} values, but pin_model's {'nq' if k == 'q' else 'nv'} is {want}")
    out = _np.empty(a.shape[:-1] + (len(mp.coords),))
    for i, c in enumerate(mp.coords):
        if k == "v":
            out[..., i] = a[..., c.idx_v]
        elif c.continuous:
            out[..., i] = _np.arctan2(a[..., c.idx_q + 1], a[..., c.idx_q])
        else:
            out[..., i] = a[..., c.idx_q]
    return out


def to_pinocchio_order(model: Any, pin_model: Any, x: Any,
                       kind: Optional[str] = None) -> _np.ndarray:
    """armsim's ``x`` (``(model.nv,)`` or ``(N, model.nv)``, in ``model.joint_names``
    order) in Pinocchio's order: a configuration of length ``pin_model.nq`` (``kind='q'``;
    a continuous joint's angle becomes ``cos, sin``) or a velocity, acceleration or torque
    of length ``pin_model.nv`` (``kind='v'``). ``kind`` may be left out when ``pin_model``
    has no continuous joints (then both are the same). Errors as
    :func:`from_pinocchio_order`."""
    mp = _mapping(model, pin_model)
    a = _as_rows(x, "x")
    n = a.shape[-1]
    if n != len(mp.coords):
        raise ArmsimError(
            f"x: {n} values for the {len(mp.coords)} coordinates of armsim's model '{model.name}'")
    k = _kind_of(kind, n, mp, "x", to_pin=True)
    out = _np.zeros(a.shape[:-1] + ((mp.pin_nq if k == "q" else mp.pin_nv),))
    for i, c in enumerate(mp.coords):
        if k == "v":
            out[..., c.idx_v] = a[..., i]
        elif c.continuous:
            out[..., c.idx_q] = _np.cos(a[..., i])
            out[..., c.idx_q + 1] = _np.sin(a[..., i])
        else:
            out[..., c.idx_q] = a[..., i]
    return out
