#!/usr/bin/env bash
# Builds the Python wheel (python/, maturin, abi3), installs it into a venv with the test
# tools (Pinocchio and example-robot-data as references, Ray, matplotlib, rerun-sdk) and
# runs pytest on python/tests (which also runs examples/python). Prints the time of each
# part. The venv is target/pyvenv (override with ARMSIM_PY_VENV); the wheel lands in
# target/wheels; cargo builds in $CARGO_TARGET_DIR (default target/).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
venv=${ARMSIM_PY_VENV:-$root/target/pyvenv}
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-$root/target}
python=${PYTHON:-python3}
t0=$(date +%s)
if [ ! -x "$venv/bin/python" ]; then
    "$python" -m venv "$venv"
fi
"$venv/bin/python" -m pip install -q --upgrade pip
"$venv/bin/python" -m pip install -q "maturin>=1.7,<2" numpy pytest "pin==4.1.0" \
    "example-robot-data==6.0.0" "ray>=2" matplotlib "rerun-sdk==0.36.3"
t1=$(date +%s)
rm -rf "$root/target/wheels"
"$venv/bin/maturin" build --release -m python/Cargo.toml -o "$root/target/wheels"
"$venv/bin/python" -m pip install -q --force-reinstall --no-deps "$root"/target/wheels/armsim-*.whl
t2=$(date +%s)
# Run from outside python/ so the installed wheel is imported, not the source tree.
(cd "$root/target" && "$venv/bin/python" -m pytest -q -p no:cacheprovider "$root/python/tests")
t3=$(date +%s)
echo "python part: venv + packages $((t1 - t0)) s, wheel $((t2 - t1)) s, pytest $((t3 - t2)) s, total $((t3 - t0)) s"
