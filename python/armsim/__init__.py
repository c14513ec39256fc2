"""armsim: robot-arm kinematics and dynamics (Rust) for Python.

Pinocchio-style functions on ``Model``/``Data`` (``forward_kinematics``,
``frame_jacobian``, ``rnea``, ``aba``, ``crba``, ``compute_generalized_gravity``, the
analytical derivatives ``rnea_derivatives``, ``aba_derivatives`` and ``compute_minverse``;
``linearise_step``, the A and B of one RK4 or semi-implicit Euler step for MPC;
``frame_velocity``, ``frame_acceleration``, ``frame_classical_acceleration``,
``frame_jacobian_time_variation``; ``compute_kinetic_energy``, ``compute_potential_energy``,
``compute_coriolis_matrix``; ``center_of_mass``, ``jacobian_center_of_mass``; and
``inverse_dynamics`` / ``forward_dynamics`` with external wrenches and a payload), the
``Robot`` facade, batches on ``(N, nq)`` arrays that run on all cores without the GIL,
scenario runs and workspace sampling. ``from_pinocchio_order`` / ``to_pinocchio_order``
convert vectors between Pinocchio's joint order and armsim's (``model.joint_names``).
Loader warnings are ``LoaderWarning``s and ``model.warnings``; ``Model``, ``Data`` and
``Robot`` pickle; long batches stop on Ctrl-C. ``armsim.distributed`` shards batch IK
and workspace sampling into Ray tasks.
"""

from __future__ import annotations

import json as _json
import os as _os
import warnings as _warnings
from typing import Any, Dict, Optional

import numpy as _np

from ._armsim import (  # noqa: F401  (re-exports)
    IK_KEYWORDS,
    ArmsimError,
    Data,
    IkResult,
    LoaderWarning,
    Model,
    Planner,
    Robot,
    aba,
    aba_batch,
    aba_derivatives,
    center_of_mass,
    compute_coriolis_matrix,
    compute_generalized_gravity,
    compute_kinetic_energy,
    compute_minverse,
    compute_potential_energy,
    crba,
    fk_batch,
    forward_dynamics,
    forward_kinematics,
    frame_acceleration,
    frame_classical_acceleration,
    frame_jacobian,
    frame_jacobian_time_variation,
    frame_velocity,
    gravity_batch,
    ik_batch,
    inverse_dynamics,
    jacobian_batch,
    linearise_step,
    jacobian_center_of_mass,
    nonlinear_effects,
    plan,
    rnea,
    rnea_batch,
    crba_batch,
    rnea_derivatives,
    sample_poses,
)
from . import _armsim
from .joint_order import from_pinocchio_order, to_pinocchio_order

__all__ = [
    "ArmsimError", "LoaderWarning", "Data", "IkResult", "Model", "Planner", "Robot",
    "IK_KEYWORDS", "from_pinocchio_order", "to_pinocchio_order",
    "forward_kinematics", "frame_jacobian", "rnea", "aba", "crba",
    "compute_generalized_gravity", "gravity", "nonlinear_effects",
    "rnea_derivatives", "aba_derivatives", "compute_minverse", "linearise_step",
    "rnea_derivatives", "aba_derivatives", "compute_minverse",
    "frame_velocity", "frame_acceleration", "frame_classical_acceleration",
    "frame_jacobian_time_variation", "compute_kinetic_energy", "compute_potential_energy",
    "compute_coriolis_matrix", "center_of_mass", "jacobian_center_of_mass",
    "inverse_dynamics", "forward_dynamics",
    "rnea_batch", "aba_batch", "crba_batch", "gravity_batch", "fk_batch", "jacobian_batch", "ik_batch",
    "sample_poses", "run_scenario", "workspace", "plan",
]

#: Short name of :func:`compute_generalized_gravity`.
gravity = compute_generalized_gravity


def run_scenario(path: "str | _os.PathLike[str]", out_dir: Optional[str] = None,
                 write_files: bool = True) -> Dict[str, Any]:
    """Runs a scenario file (``armsim run``) and returns its JSON report as a dict.

    Arm scenarios write their files (plots, report, MCAP) to ``out_dir`` (default: the
    file's ``[outputs] dir`` or ``out/<name>``) unless ``write_files`` is false. A robot,
    scene or mesh file (``.urdf``, ``.srdf``, ``.yaml``, ``.dae``, ...) is refused with a
    pointer to what reads it.
    """
    suffix = _os.path.splitext(_os.fspath(path))[1].lower()
    readers = {
        ".urdf": "a robot model: load it with armsim.Model.from_file",
        ".xacro": "a xacro template: expand it to URDF first (xacro robot.urdf.xacro > robot.urdf)",
        ".srdf": "a MoveIt SRDF: pass it as srdf= to armsim.plan or armsim.Planner",
        ".yaml": "a MoveIt scene or request: pass it as scene= or request= to armsim.plan",
        ".yml": "a MoveIt scene or request: pass it as scene= or request= to armsim.plan",
        ".dae": "a mesh: meshes are read through the URDF that references them",
        ".stl": "a mesh: meshes are read through the URDF that references them",
        ".obj": "a mesh: meshes are read through the URDF that references them",
        ".mcap": "a recording: open it with `armsim view`",
    }
    if suffix in readers:
        raise ArmsimError(
            f"run_scenario: {_os.fspath(path)} is {readers[suffix]}; run_scenario takes a "
            "scenario TOML (see scenarios/)")
    text = _armsim.run_scenario_json(_os.fspath(path),
                                     None if out_dir is None else _os.fspath(out_dir),
                                     write_files)
    return _json.loads(text)


def workspace(model: Model, samples: int = 1 << 16, seed: int = 0, voxel: float = 0.02,
              tool: Optional[str] = None, sampling: str = "sobol", replicates: int = 8,
              planar: Optional[bool] = None, extras: bool = True, keep_points: int = 1000,
              target_rel_error: Optional[float] = None) -> Dict[str, Any]:
    """Samples the reachable workspace of ``tool`` (default: the deepest link).

    Returns a dict: ``estimate`` (m³, or m² when planar), ``interval`` (95 %; the upper
    end is None when only a lower bound is known), ``interval_kind``, ``unit``,
    ``planar``, ``points`` ``(k, 3)``, ``q`` ``(k, nv)``, ``manipulability`` ``(k,)``
    (the first ``keep_points`` samples of the Jacobian pass) and ``report`` (the full
    result, as ``armsim workspace --json``). When too few samples give only a lower
    bound (``interval_kind == "lower_bound"``), a ``UserWarning`` says so.
    """
    text, points, q, manip = _armsim.workspace_json(
        model, samples, seed, voxel, tool, sampling, replicates, planar, extras,
        keep_points, target_rel_error)
    report = _json.loads(text)
    if report["interval_kind"] == "lower_bound":
        _warnings.warn(
            f"armsim.workspace: {samples} samples give only a lower bound of the "
            f"{'area' if report['planar'] else 'volume'} (estimate "
            f"{report['area_m2'] if report['planar'] else report['volume_m3']}); "
            f"about {report.get('samples_needed')} samples give a two-sided interval "
            "(or pass target_rel_error)",
            UserWarning, stacklevel=2)
    planar_ = bool(report["planar"])
    interval = report["area_interval_m2"] if planar_ else report["volume_interval_m3"]
    return {
        "estimate": report["area_m2"] if planar_ else report["volume_m3"],
        "interval": tuple(interval) if interval is not None else (None, None),
        "interval_kind": report["interval_kind"],
        "unit": "m^2" if planar_ else "m^3",
        "planar": planar_,
        "points": points,
        "q": q,
        "manipulability": manip,
        "report": report,
    }


def pose(rotation: Any = None, translation: Any = None) -> _np.ndarray:
    """A 4×4 homogeneous transform from a 3×3 rotation and a translation.

    Raises ``ArmsimError`` for a non-finite entry, a rotation that is not orthonormal with
    determinant 1 (to 1e-6), or a translation beyond 1e9 m."""
    t = _np.eye(4)
    if rotation is not None:
        r = _np.asarray(rotation, dtype=float)
        if r.shape != (3, 3):
            raise ArmsimError(f"pose: rotation of shape {r.shape}, expected (3, 3)")
        if not _np.all(_np.isfinite(r)):
            raise ArmsimError("pose: the rotation is not finite")
        off = _np.abs(r.T @ r - _np.eye(3)).max()
        if off > 1e-6 or abs(_np.linalg.det(r) - 1.0) > 1e-6:
            raise ArmsimError(
                f"pose: the rotation is not orthonormal (|RᵀR − I| = {off:.1e}, det = {_np.linalg.det(r):.6f})")
        t[:3, :3] = r
    if translation is not None:
        p = _np.asarray(translation, dtype=float)
        if p.shape != (3,):
            raise ArmsimError(f"pose: translation of shape {p.shape}, expected (3,)")
        if not _np.all(_np.isfinite(p)) or _np.abs(p).max() > 1e9:
            raise ArmsimError(f"pose: the translation {p.tolist()} is not finite or beyond 1e9 m")
        t[:3, 3] = p
    return t
