#!/usr/bin/env bash
# The independent Python peer (tests/peer/nav2_peer.py) against the node and the simulated
# Bujold: installs PyPI's eclipse-zenoh in a virtual environment under target/, then runs
# the ignored harness test that starts the node and the simulator on 127.0.0.1 and the
# peer as a child process. Exit code 0 when the peer's checks hold.
set -euo pipefail
cd "$(dirname "$0")/../.."
venv=target/peer-venv
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
"$venv/bin/pip" install --quiet --disable-pip-version-check "eclipse-zenoh==1.10.2"
MARSUPIAL_PY_PEER="$PWD/$venv/bin/python" nice -n 10 cargo test --profile ci-ros2 --features ros2 \
    --test ros2_bridge -- --ignored --nocapture an_independent_python_peer
