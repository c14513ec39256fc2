#!/usr/bin/env bash
# The README's test command (what .ci/run runs from a clean clone): the Rust tests, then
# the Python package (wheel built and installed into a venv, pytest; tools/test_python.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --release
tools/test_python.sh
