#!/bin/sh
# make-man.sh OUT.1: gonio's man page, made by help2man from `gonio --help` with every
# command's own --help as a section, so the page says what the program says.
# Environment: GONIO (the program).
set -eu
out=$1
inc=$(mktemp)
trap 'rm -f "$inc"' EXIT
{
    echo "[DESCRIPTION]"
    echo "Every command has --help; options take their value as --opt value or --opt=value."
    echo "[COMMANDS]"
    for c in $("$GONIO" --help | sed -n 's/^  \([a-z][a-z]*\)  *.*/\1/p'); do
        echo ".SS $c"
        echo ".nf"
        # roff: a backslash is \e, and a line may not start with . or '.
        "$GONIO" "$c" --help | sed -e 's/\\/\\e/g' -e "s/^\([.']\)/\\\\\&\1/"
        echo ".fi"
    done
    echo "[EXIT STATUS]"
    echo "0 ok, 1 bad input or failed render, 2 bad usage; 128 + N after signal N (130 after"
    echo "Ctrl-C, 143 after SIGTERM): the render stopped after its pass and wrote what it had."
    echo "A second signal quits at once and leaves no output."
}>"$inc"
help2man --no-info --name="a physically based renderer (glTF, Vulkan compute)" \
    --include="$inc" --output="$out" "$GONIO"
