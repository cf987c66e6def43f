#!/usr/bin/env bash
# peer.sh: the Mitsuba converter of make bench-peer (tests/peer), checked cheaply on the white
# furnace: gonio and Mitsuba each render 0.8 inside the sphere (the analytic answer) and the
# same image mean, within 4 standard errors of their own noise. Skips, saying so, where
# make bench-peer has not installed Mitsuba in build/peer/venv (it installs nothing itself).
. "$(dirname "$0")/../lib.sh"
. tests/peer/env.sh
peer_env || skip_all "$PEER_WHY"
check "the furnace agrees in gonio, Mitsuba and analytically" \
    "$PEER_PY" tests/peer/peer.py --gonio "$GONIO" --out "$tmp" --check-furnace
sed 's/^/  /' "$tmp/out"
finish
