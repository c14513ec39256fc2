"""The notebook-style example under examples/python runs end to end: scenario report,
torque plot (PNG) and a Rerun recording (.rrd)."""

from __future__ import annotations

import subprocess
import sys

import pytest

from conftest import ROOT

pytest.importorskip("matplotlib")
pytest.importorskip("rerun")


def test_scenario_torques_example_writes_the_plot_and_the_recording(tmp_path):
    script = ROOT / "examples" / "python" / "scenario_torques.py"
    run = subprocess.run([sys.executable, str(script), str(tmp_path)], capture_output=True,
                         text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert "planar_2r: ok=True" in run.stdout
    png, rrd = tmp_path / "torques.png", tmp_path / "torques.rrd"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10_000
    assert rrd.read_bytes()[:4] == b"RRF2" and rrd.stat().st_size > 1_000
    assert (tmp_path / "run" / "planar_2r.json").is_file()
