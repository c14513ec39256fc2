#!/usr/bin/env bash
# Build the Pinocchio timing harness against the `pin` PyPI wheel (cmeel layout).
#
#   tools/pinocchio/build.sh            -> tools/pinocchio/build/bench_hdr, bench_lib
#
# Env overrides: PYTHON (default python3), CMEEL_PREFIX (default
# <site-packages>/cmeel.prefix of $PYTHON), CXX (default g++).
#
# Flags: -O3 -DNDEBUG, baseline x86-64 (-march=x86-64 -mtune=generic, i.e. SSE2
# only, NO -march=native), C++17. rpath points at the wheel's lib dir.
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
PYTHON="${PYTHON:-python3}"
CXX="${CXX:-g++}"
if [[ -z "${CMEEL_PREFIX:-}" ]]; then
  CMEEL_PREFIX="$("$PYTHON" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')/cmeel.prefix"
fi
INC="$CMEEL_PREFIX/include"
LIB="$CMEEL_PREFIX/lib"
for f in "$INC/pinocchio/config.hpp" "$INC/eigen3/Eigen/Core" "$INC/urdfdom_headers/urdf_model/model.h" \
         "$LIB/libpinocchio_default.so" "$LIB/libpinocchio_parsers.so"; do
  [[ -e "$f" ]] || { echo "missing $f -- run: $PYTHON -m pip install -r $HERE/requirements.txt" >&2; exit 1; }
done

mkdir -p "$HERE/build"
COMMON=(
  -std=c++17 -O3 -DNDEBUG -march=x86-64 -mtune=generic
  -I"$INC" -I"$INC/eigen3" -I"$INC/urdfdom" -I"$INC/urdfdom_headers"
  # Interface definitions of pinocchio::pinocchio_headers / pinocchio_parsers
  # (lib/cmake/pinocchio/pinocchioTargets.cmake of the wheel):
  -DBOOST_MPL_LIMIT_LIST_SIZE=30 -DBOOST_MPL_LIMIT_VECTOR_SIZE=30
  -DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS -DBOOST_FUSION_INVOKE_MAX_ARITY=12
  -DPINOCCHIO_WITH_URDFDOM -DPINOCCHIO_URDFDOM_HEADERS_MAJOR_VERSION=3
  -DPINOCCHIO_URDFDOM_HEADERS_MINOR_VERSION=0 -DPINOCCHIO_URDFDOM_HEADERS_PATCH_VERSION=0
  -Wno-deprecated-declarations
)
LINK=(
  -L"$LIB" -Wl,-rpath,"$LIB"
  -lpinocchio_parsers -lpinocchio_default -lurdfdom_model -lboost_filesystem -lboost_serialization
)
# Compiled one after the other on purpose (small shared machine).
# hdr: algorithms instantiated and compiled here with the flags above.
"$CXX" "${COMMON[@]}" "$HERE/bench.cpp" -o "$HERE/build/bench_hdr" "${LINK[@]}"
# lib: algorithms come from the wheel's pre-compiled libpinocchio_default.so.
"$CXX" "${COMMON[@]}" -DBENCH_LIB "$HERE/bench.cpp" -o "$HERE/build/bench_lib" "${LINK[@]}"
echo "built $HERE/build/bench_hdr $HERE/build/bench_lib (pinocchio $(grep -m1 'define PINOCCHIO_VERSION ' "$INC/pinocchio/config.hpp" | awk '{print $NF}'), prefix $CMEEL_PREFIX)" >&2
