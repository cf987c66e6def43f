#!/usr/bin/env bash
# basisu.sh DIR: Basis Universal's transcoder and encoder sources for KHR_texture_basisu, as the
# crate basis-universal-sys ships them (Debian packages neither), fetched by the machine's cargo
# from its configured registry and unpacked into DIR/src; DIR/gonio_basisu.mk and
# DIR/gonio_basisu.h say whether they are there, with the crate's and Basis Universal's
# versions, or why not. The Makefile compiles them into libraries (make's own step, not here).
#
# Once DIR/src is there nothing is fetched again: the build works offline. Without cargo, or
# when cargo cannot fetch, the build goes on without KTX2 support and says why (gonio --version,
# and the error a KTX2 texture gives); remove DIR (or make clean) to try again.
#
# Only the crate's C++ sources are used, never its Rust code: a throwaway Cargo package in
# DIR/fetch depends on the pinned version, `cargo metadata` resolves and unpacks it into cargo's
# own cache and says where, and the transcoder/ and encoder/ folders are copied from there.
# Zstandard (KTX2's UASTC supercompression) comes from Debian's libzstd-dev instead of the copy
# the crate ships: DIR/src/zstd/zstd.h, the header the sources include by that relative path,
# forwards to the system's.
set -u
CRATE=basis-universal-sys
CRATE_VERSION=0.3.1 # Basis Universal 1.16
dir=${1:?usage: basisu.sh DIR}
mkdir -p "$dir"

# without(REASON): the build goes on without KTX2 support.
without() {
    set -- "$(printf '%s' "$1" | tr -d '"\\\n' | head -c 300)" # a C string's contents
    echo "gonio: building without KTX2 (Basis Universal) support: $1" >&2
    printf '# written by deps/basisu.sh\nBASISU :=\n' >"$dir/gonio_basisu.mk"
    printf '/* written by deps/basisu.sh */\n#define GONIO_BASISU 0\n#define GONIO_BASISU_MISSING "%s"\n' \
        "$1" >"$dir/gonio_basisu.h"
    exit 0
}

if [ ! -f "$dir/src/transcoder/basisu_transcoder.cpp" ]; then
    command -v cargo >/dev/null 2>&1 || without "cargo is not installed (it fetches the crate $CRATE)"
    mkdir -p "$dir/fetch"
    cat >"$dir/fetch/Cargo.toml" <<EOF
# written by deps/basisu.sh: only for cargo to fetch and unpack the crate's sources
[package]
name = "gonio-basisu-fetch"
version = "0.0.0"
edition = "2018"
publish = false

[lib]
path = "lib.rs"

[dependencies]
$CRATE = "=$CRATE_VERSION"

[workspace]
EOF
    : >"$dir/fetch/lib.rs"
    # Offline first: a crate cargo already holds needs no network.
    meta=$(cargo metadata --format-version 1 --manifest-path "$dir/fetch/Cargo.toml" --offline 2>/dev/null) ||
        meta=$(timeout 600 cargo metadata --format-version 1 --manifest-path "$dir/fetch/Cargo.toml" 2>"$dir/fetch/cargo.log") ||
        without "cargo could not fetch the crate $CRATE $CRATE_VERSION ($(grep -m 1 'error' "$dir/fetch/cargo.log" || tail -n 1 "$dir/fetch/cargo.log"))"
    manifest=$(printf '%s' "$meta" | grep -o "\"manifest_path\":\"[^\"]*/$CRATE-$CRATE_VERSION/Cargo.toml\"" | head -n 1 |
        sed 's/^"manifest_path":"//; s/"$//')
    src=$(dirname "$manifest")/vendor/basis_universal
    [ -n "$manifest" ] && [ -f "$src/transcoder/basisu_transcoder.cpp" ] ||
        without "the crate $CRATE $CRATE_VERSION has no vendor/basis_universal/transcoder"
    rm -rf "$dir/src.tmp" && mkdir -p "$dir/src.tmp/zstd" &&
        cp -R "$src/transcoder" "$src/encoder" "$src/LICENSE" "$dir/src.tmp/" &&
        printf '/* written by deps/basisu.sh: Debian'"'"'s libzstd instead of the copy the crate ships */\n#include <zstd.h>\n' \
            >"$dir/src.tmp/zstd/zstd.h" &&
        mv "$dir/src.tmp" "$dir/src" || without "could not copy the sources from $src"
fi
version=$(sed -n 's/^#define BASISU_LIB_VERSION_STRING "\(.*\)"/\1/p' "$dir/src/encoder/basisu_comp.h")
printf '# written by deps/basisu.sh\nBASISU := 1\n' >"$dir/gonio_basisu.mk"
printf '/* written by deps/basisu.sh */\n#define GONIO_BASISU 1\n#define GONIO_BASISU_VERSION "%s"\n#define GONIO_BASISU_CRATE "%s %s"\n' \
    "$version" "$CRATE" "$CRATE_VERSION" >"$dir/gonio_basisu.h"
echo "gonio: Basis Universal $version from the crate $CRATE $CRATE_VERSION in $dir/src" >&2
