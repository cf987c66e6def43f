# env.sh: sourced by tests/peer/run.sh and tests/regress/peer.sh. peer_env [install]: sets
# PEER_PY (the venv's python) and DRJIT_LIBLLVM_PATH when build/peer/venv holds a Mitsuba 3
# whose LLVM backend runs; with `install`, makes that venv first where it is missing.
# Dr.Jit's LLVM backend aborts with Debian 12's libLLVM (14 and 15) and needs a newer one:
# PyPI's karellen-llvm-core ships a shared libLLVM 23 (with the libc++ it links), which
# Dr.Jit loads from DRJIT_LIBLLVM_PATH. (llvmlite links LLVM statically, apt.llvm.org is
# out of reach.) Versions pinned: the ones this bench was measured with.
PEER_VENV=${PEER_VENV:-build/peer/venv}
PEER_PIP="mitsuba==3.9.1 drjit==1.5.0 numpy==2.4.6 karellen-llvm-core==23.1.4.post8"
peer_env() {
    PEER_PY=$PEER_VENV/bin/python
    if [ "${1:-}" = install ] && ! "$PEER_PY" -c 'import mitsuba, drjit, numpy' >/dev/null 2>&1; then
        rm -rf "$PEER_VENV"
        echo "bench-peer: installing $PEER_PIP into $PEER_VENV"
        if ! { python3 -m venv "$PEER_VENV" && "$PEER_VENV/bin/pip" install -q $PEER_PIP; }; then
            rm -rf "$PEER_VENV"
            PEER_WHY="Mitsuba 3 could not be installed (python3 -m venv, pip install $PEER_PIP)"
            return 1
        fi
    fi
    if [ ! -x "$PEER_PY" ]; then
        PEER_WHY="$PEER_VENV is absent (make bench-peer installs Mitsuba 3 there)"
        return 1
    fi
    DRJIT_LIBLLVM_PATH=$(ls "$PWD/$PEER_VENV"/lib/libLLVM.so.* 2>/dev/null | head -n 1)
    export DRJIT_LIBLLVM_PATH
    # A tiny render, not just an import: libLLVM 14 loads, then aborts compiling a kernel.
    if ! "$PEER_PY" -c 'import mitsuba as mi; mi.set_variant("llvm_ad_rgb"); import drjit as dr
s = mi.cornell_box(); s["sensor"]["film"].update(width=8, height=8)
dr.eval(mi.render(mi.load_dict(s), spp=1))' >/dev/null 2>&1; then
        PEER_WHY="Mitsuba 3's LLVM variant does not run here (libLLVM: ${DRJIT_LIBLLVM_PATH:-none})"
        return 1
    fi
}
