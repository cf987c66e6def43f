#!/usr/bin/env python3
"""doc_claims.py DOC...: checks what a reference page claims of the source tree, where a
program can: every path it names in backquotes exists (but templates: NAME, SUITE, *); every
`name` (`path`) it pairs names something that file has; every diff it shows applies (its
removed and context lines are lines of the file it names, in that order); and the feature-bit
recipe's count (glsl/lib/shared.h's GN_FEAT(n) in use, the next free one) and its free
material words (glsl/lib/material.h) are today's. Prints each false claim; exit 1 if any."""
import os
import re
import sys

bad = 0


def claim(ok, doc, what):
    global bad
    if not ok:
        print(f"{doc}: {what}")
        bad = 1


def read(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


def feature_bits():
    """The bits glsl/lib/shared.h defines (#define GN_FEAT_X GN_FEAT(n)): their count."""
    used = [int(n) for n in re.findall(r"^#define GN_FEAT_\w+ GN_FEAT\((\d+)\)", read("glsl/lib/shared.h"), re.M)]
    assert used, "no GN_FEAT(n) definitions in glsl/lib/shared.h"
    return max(used) + 1, len(set(used))


def check_doc(doc):
    text = read(doc)
    for tok in sorted(set(re.findall(r"`([^`\s]+)`", text))):
        if re.match(r"(src|glsl|tests|docs|deps|scenes|farm|completion)/", tok) and not re.search(r"NAME|SUITE|\*", tok):
            claim(os.path.exists(tok.rstrip(":,.")), doc, f"names {tok}, which does not exist")
    for name, path in re.findall(r"`([A-Za-z_]\w*)(?:\(\))?` \(`([\w./-]+\.(?:c|h|cpp|glsl|comp|sh|py))`\)", text):
        if os.path.exists(path):
            claim(re.search(r"\b" + re.escape(name) + r"\b", read(path)) is not None, doc,
                  f"says `{name}` is in {path}; it is not")
    # ```diff blocks: each file's - and context lines, in order, are lines of the file
    for block in re.findall(r"```diff\n(.*?)```", text, re.S):
        for part in re.split(r"^--- a/", block, flags=re.M)[1:]:
            path = part.split("\n", 1)[0].strip()
            if not os.path.exists(path):
                claim(False, doc, f"shows a diff of {path}, which does not exist")
                continue
            lines = [l.strip() for l in read(path).split("\n")]
            at = 0
            for l in part.split("\n")[1:]:
                if l.startswith("+++") or l.startswith("+") or l.startswith("@@") or not l.strip():
                    continue
                want = l[1:].strip()
                try:
                    at = lines.index(want, at) + 1
                except ValueError:
                    claim(False, doc, f"its diff of {path} does not apply: no line '{want}' (in that order)")
                    break
    nxt, count = feature_bits()
    for n, k in re.findall(r"There are 64 bits, (\d+)\s+in use \(`GN_FEAT\((\d+)\)` is the next", text):
        claim(int(n) == count and int(k) == nxt, doc,
              f"says {n} feature bits are in use and GN_FEAT({k}) is the next; glsl/lib/shared.h has {count}, "
              f"the next GN_FEAT({nxt})")
    for k in re.findall(r"`GN_FEAT\((\d+)\)` in\s+`glsl/lib/shared.h`", text):
        claim(int(k) == nxt, doc, f"names GN_FEAT({k}) as a new bit; the next free one is GN_FEAT({nxt})")
    material = read("glsl/lib/material.h")
    for names in re.findall(r"((?:`\w+`(?:, | and )?)+) (?:is a free scalar|are free scalars)", text):
        for name in re.findall(r"`(\w+)`", names):
            claim(re.search(r"FIELD\(" + name + r", float,", material) is not None, doc,
                  f"says {name} is a free scalar of GnMaterial; glsl/lib/material.h has no such FIELD row")


for d in sys.argv[1:]:
    check_doc(d)
sys.exit(bad)
