#!/usr/bin/env bash
# One command on a fresh Debian machine: system packages, a virtualenv with
# everything, then the main job at a small scale.  Safe to run again.
set -euo pipefail
cd "$(dirname "$0")"

APT_PACKAGES="python3-venv python3-dev build-essential cmake libcgal-dev libgmp-dev libmpfr-dev"
if command -v apt-get >/dev/null; then
  missing=$(for p in $APT_PACKAGES; do dpkg -s "$p" >/dev/null 2>&1 || echo "$p"; done)
  if [ -n "$missing" ]; then
    if [ "$(id -u)" = 0 ]; then
      apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $missing
    else
      echo "Missing system packages; as root run:  apt-get install -y $(echo $missing)" >&2
      exit 1
    fi
  fi
fi

bash .ci/install
echo
echo "== main job (small scale) =="
.venv/bin/python -m experiments.bench_dc --scale small
