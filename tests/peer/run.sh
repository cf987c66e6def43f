#!/usr/bin/env bash
# run.sh GONIO [peer.py options]: make bench-peer. Installs Mitsuba 3 in build/peer/venv
# where it is missing (deps/mitsuba.sh), then runs peer.py; where Mitsuba cannot be had it
# says why and exits 0.
set -u
cd "$(dirname "$0")/../.."
. tests/peer/env.sh
G=${1:-build/gonio}
shift
if ! deps/mitsuba.sh "$PEER_VENV"; then
    echo "bench-peer: skipped: Mitsuba 3 could not be installed"
    exit 0
fi
if ! peer_env; then
    echo "bench-peer: skipped: $PEER_WHY"
    exit 0
fi
exec "$PEER_PY" tests/peer/peer.py --gonio "$G" "$@"
