#!/usr/bin/env bash
# One command on a fresh Debian machine: system packages (as root), a
# virtualenv with everything, the CGAL driver, then the main job at a small
# scale.  Safe to run again.
set -euo pipefail
cd "$(dirname "$0")"
bash .ci/install
echo
echo "== main job: experiments at the default scale (about 10 minutes on 2 cores) =="
.venv/bin/python -m experiments.all --scale default
