#!/usr/bin/env bash
# mitsuba.sh VENV: Mitsuba 3 for make bench-peer (tests/peer), in the Python venv VENV (made
# with python3 -m venv: deps/debian.sh peer), its packages fetched by the venv's pip from the
# machine's configured index. Dr.Jit's LLVM backend aborts with Debian 12's libLLVM (14 and
# 15) and needs a newer one: karellen-llvm-core ships a shared libLLVM 23 (with the libc++ it
# links), which tests/peer/env.sh points Dr.Jit at. (llvmlite links LLVM statically.)
# Versions pinned: the ones the bench was measured with.
#
# A VENV whose python imports them is left as it is; anything else there is replaced. When
# they cannot be installed, VENV is removed and the script fails, saying so.
set -u
PIP="mitsuba==3.9.1 drjit==1.5.0 numpy==2.4.6 karellen-llvm-core==23.1.4.post8"
venv=${1:?usage: mitsuba.sh VENV}

if "$venv/bin/python" -c 'import mitsuba, drjit, numpy' >/dev/null 2>&1; then
    echo "gonio: Mitsuba 3 is in $venv (remove it to install again)"
    exit 0
fi
rm -rf "$venv"
echo "gonio: installing $PIP into $venv"
# shellcheck disable=SC2086 # (PIP: one requirement a word)
if ! { python3 -m venv "$venv" && "$venv/bin/pip" install -q $PIP; }; then
    rm -rf "$venv"
    echo "gonio: Mitsuba 3 could not be installed (python3 -m venv, pip install $PIP)"
    exit 1
fi
echo "gonio: Mitsuba 3 is in $venv"
