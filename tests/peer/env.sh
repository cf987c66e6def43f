# env.sh: sourced by tests/peer/run.sh and tests/regress/peer.sh. peer_env: sets PEER_PY (the
# venv's python) and DRJIT_LIBLLVM_PATH when build/peer/venv holds a Mitsuba 3 whose LLVM
# backend runs (deps/mitsuba.sh makes that venv); otherwise returns 1 with PEER_WHY saying
# why. Dr.Jit loads its libLLVM from DRJIT_LIBLLVM_PATH: the venv's (karellen-llvm-core's
# libLLVM 23), since Debian 12's (14 and 15) makes its LLVM backend abort.
PEER_VENV=${PEER_VENV:-build/peer/venv}
peer_env() {
    PEER_PY=$PEER_VENV/bin/python
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
