#!/usr/bin/env bash
# The FMU tests with a real importer: builds hydrocyl and the slave library
# (libhydrocyl_fmu.so, found next to hydrocyl), makes a venv with FMPy and
# pytest from PyPI under the cargo target folder, and runs the pytest files
# in crates/fmu/tests/python. Extra arguments go to pytest.
#   crates/fmu/tests/run_fmpy_tests.sh [-k match -s]
set -euo pipefail
cd "$(dirname "$0")/../../.."
target="${CARGO_TARGET_DIR:-target}"
profile="${HYDROCYL_FMU_PROFILE:-debug}"
flag=""; [ "$profile" = release ] && flag="--release"
cargo build $flag -p hydrocyl-fmu -p hydrocyl-cli
venv="$target/fmpy-venv"
if [ ! -x "$venv/bin/pytest" ] || ! "$venv/bin/python" -c "import fmpy" 2>/dev/null; then
  python3 -m venv "$venv"
  "$venv/bin/pip" install --quiet --upgrade pip
  "$venv/bin/pip" install --quiet "fmpy>=0.3.20" "pytest>=7"
fi
HYDROCYL="$(cd "$target/$profile" && pwd)/hydrocyl" \
  "$venv/bin/python" -m pytest -q crates/fmu/tests/python "$@"
