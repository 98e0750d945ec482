#!/bin/sh
# Installs what Dovetail needs to build and test on Debian 12 (as root).
# Runs apt only when something is missing, so it is cheap to call every time.
set -eu

# Build and library dependencies.
packages="g++ cmake make pkg-config ccache libeigen3-dev libassimp-dev libtbb-dev libgtest-dev libqhull-dev libosmesa6-dev libpng-dev liblua5.4-dev nlohmann-json3-dev"
# Test-only: exact oracle for the triangle test, and the model files of the import tests.
packages="$packages libcgal-dev assimp-testmodels"
# Test-only: a real headless browser opens the regress HTML report.
packages="$packages chromium"
# Bench-only peers (optional for the library, used by bench/).
packages="$packages libfcl-dev libbullet-dev libccd-dev"
# Bench-only: the charts of docs/benchmarks.md (scripts/charts.sh).
packages="$packages gnuplot-nox"
# Fuzzing only: clang and its libFuzzer runtime (scripts/fuzz.sh, docs/reliability.md).
packages="$packages clang libfuzzer-14-dev"

missing=""
for p in $packages; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing="$missing $p"
  fi
done

if [ -n "$missing" ]; then
  echo "install-deps: installing$missing" >&2
  if [ "$(id -u)" -ne 0 ]; then
    echo "install-deps: missing packages and not root; run as root or install:$missing" >&2
    exit 1
  fi
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  # shellcheck disable=SC2086
  apt-get install -y -qq --no-install-recommends $missing >/dev/null
fi
