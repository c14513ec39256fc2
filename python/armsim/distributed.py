"""Scale-out on Ray: batch IK, workspace point clouds and workspace sweeps sharded into
Ray tasks by index (seed) range.

Every result is identical to the single-process call, whatever the shard count:
``ik_batch`` gives target ``i`` the IK seed ``seed + i`` (``armsim.ik_batch(...,
start=s)`` on the shard that starts at ``s``), ``workspace_points`` draws configuration
``i`` from a counter-based stream of ``(seed, i)`` (``armsim.sample_poses``), and
``workspace_sweep`` runs one ``armsim.workspace`` per seed. The model travels to the
workers pickled (its source text and options) through the object store, once.

Ray is started with ``ray.init()`` if it is not running yet; to use a real cluster,
call ``ray.init(address="ray://<head>:10001")`` (or run under ``ray job submit``, or set
``RAY_ADDRESS``) before calling these functions. Each worker needs this armsim wheel
installed: build it once (``pip wheel ./python`` in the armsim repository, or take
``target/wheels/armsim-*.whl`` from ``tools/test_python.sh``) and install that file on
every node, or list it in Ray's ``runtime_env={"py_modules": [...]}``. Do not
``pip install armsim`` from PyPI: that name belongs to an unrelated package.
"""

from __future__ import annotations

from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

import armsim as am


def _ray():
    try:
        import ray
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError("armsim.distributed needs Ray: pip install 'ray>=2'") from e
    if not ray.is_initialized():
        ray.init()
    return ray


def _ranges(n: int, shards: Optional[int], min_size: int) -> List[Tuple[int, int]]:
    """Contiguous index ranges covering 0..n."""
    if shards is None:
        shards = max(1, int(_ray().cluster_resources().get("CPU", 1)))
    shards = max(1, min(shards, (n + min_size - 1) // max(min_size, 1) or 1))
    edges = np.linspace(0, n, shards + 1).round().astype(int)
    return [(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:]) if b > a]


def _ik_shard(model: am.Model, frame: Any, targets: np.ndarray, start: int,
              kwargs: Dict[str, Any]) -> Dict[str, Any]:
    return am.ik_batch(model, frame, targets, start=start, **kwargs)


def _poses_shard(model: am.Model, n: int, seed: int, frame: Any, start: int):
    return am.sample_poses(model, n, seed=seed, frame=frame, start=start)


def _workspace_task(model: am.Model, seed: int, kwargs: Dict[str, Any]) -> Dict[str, Any]:
    return am.workspace(model, seed=seed, **kwargs)


def ik_batch(model: am.Model, frame: Any, targets: np.ndarray, shards: Optional[int] = None,
             **kwargs: Any) -> Dict[str, Any]:
    """``armsim.ik_batch`` over Ray tasks: the same dict, the same numbers."""
    ray = _ray()
    targets = np.ascontiguousarray(targets, dtype=float)
    task = ray.remote(_ik_shard)
    mref = ray.put(model)
    parts = ray.get([task.remote(mref, frame, targets[a:b], a, kwargs)
                     for a, b in _ranges(len(targets), shards, 1)])
    if not parts:
        return am.ik_batch(model, frame, targets, **kwargs)
    out: Dict[str, Any] = {}
    for key in parts[0]:
        vals = [p[key] for p in parts]
        out[key] = np.concatenate(vals) if isinstance(vals[0], np.ndarray) else sum(vals, [])
    return out


def workspace_points(model: am.Model, n: int, seed: int = 0, frame: Any = None,
                     shards: Optional[int] = None) -> Tuple[np.ndarray, np.ndarray]:
    """``armsim.sample_poses(model, n, seed, frame)`` over Ray tasks: configurations
    ``(n, nv)`` and tool placements ``(n, 4, 4)``, identical to the single-process call."""
    ray = _ray()
    task = ray.remote(_poses_shard)
    mref = ray.put(model)
    parts = ray.get([task.remote(mref, b - a, seed, frame, a)
                     for a, b in _ranges(n, shards, 1024)])
    if not parts:
        return am.sample_poses(model, 0, seed=seed, frame=frame)
    return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])


def workspace_sweep(model: am.Model, seeds: Sequence[int], **kwargs: Any) -> List[Dict[str, Any]]:
    """One ``armsim.workspace(model, seed=s, **kwargs)`` per seed, as Ray tasks (a
    parameter sweep; each result equals the single-process run with that seed, apart from
    the wall time and thread count in ``report``)."""
    ray = _ray()
    task = ray.remote(_workspace_task)
    mref = ray.put(model)
    return ray.get([task.remote(mref, int(s), kwargs) for s in seeds])
