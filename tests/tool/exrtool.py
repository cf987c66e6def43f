#!/usr/bin/env python3
"""exrtool.py: reads and writes uncompressed scanline OpenEXR files (what `gonio render
--compression none` writes) with Python alone, to make the damaged and hostile EXRs of the
tests: an independent reader and writer, not gonio's.

  exrtool.py poke IN OUT CHANNEL X Y VALUE     set one value (nan, inf, -inf, any float)
  exrtool.py retype IN OUT CHANNEL half|uint   store a channel as half (values converted) or
                                               as uint (the same 4 bytes, read as integers)
  exrtool.py attr IN OUT NAME int|string VALUE set (or add) a header attribute
  exrtool.py window IN OUT DX DY               move the data window by (DX, DY) pixels
  exrtool.py mutate IN OUT SEED                one random damage of the kinds above, or of
                                               the file's bytes (the partial-file campaign)
  exrtool.py nonfinite IN                      prints how many values are NaN or infinite
"""
import math
import random
import struct
import sys

MAGIC = b"\x76\x2f\x31\x01"
UINT, HALF, FLOAT = 0, 1, 2
SIZE = {UINT: 4, HALF: 2, FLOAT: 4}
FMT = {UINT: "I", HALF: "e", FLOAT: "f"}


def read(path):
    """(attrs: list of [name, type, bytes], channels: {name: [type, values]}) of an
    uncompressed scanline EXR."""
    data = open(path, "rb").read()
    if data[:4] != MAGIC:
        raise SystemExit(f"{path}: not an OpenEXR file")
    pos, attrs = 8, []
    while data[pos] != 0:
        end = data.index(b"\0", pos)
        name = data[pos:end].decode()
        tend = data.index(b"\0", end + 1)
        typ = data[end + 1:tend].decode()
        (size,) = struct.unpack_from("<i", data, tend + 1)
        attrs.append([name, typ, data[tend + 5:tend + 5 + size]])
        pos = tend + 5 + size
    pos += 1
    a = {n: v for n, t, v in attrs}
    if a["compression"] != b"\0":
        raise SystemExit(f"{path}: compressed (write it with --compression none)")
    x0, y0, x1, y1 = struct.unpack("<4i", a["dataWindow"])
    w, h = x1 - x0 + 1, y1 - y0 + 1
    chans = parse_chlist(a["chlist"] if "chlist" in a else a["channels"])
    pos += 8 * h  # the offset table: one chunk a line
    out = {n: [t, []] for n, t in chans}
    for _ in range(h):
        pos += 8  # y, size
        for n, t in chans:
            out[n][1].extend(struct.unpack_from("<%d%s" % (w, FMT[t]), data, pos))
            pos += w * SIZE[t]
    return attrs, out


def parse_chlist(v):
    chans, pos = [], 0
    while v[pos] != 0:
        end = v.index(b"\0", pos)
        (t,) = struct.unpack_from("<i", v, end + 1)
        chans.append((v[pos:end].decode(), t))
        pos = end + 1 + 16
    return chans


def write(path, attrs, chans):
    names = sorted(chans)
    chl = b"".join(n.encode() + b"\0" + struct.pack("<iB3xii", chans[n][0], 0, 1, 1) for n in names) + b"\0"
    attrs = [[n, t, chl if n == "channels" else v] for n, t, v in attrs]
    a = {n: v for n, t, v in attrs}
    x0, y0, x1, y1 = struct.unpack("<4i", a["dataWindow"])
    w, h = x1 - x0 + 1, y1 - y0 + 1
    head = MAGIC + struct.pack("<I", 2)
    for n, t, v in attrs:
        head += n.encode() + b"\0" + t.encode() + b"\0" + struct.pack("<i", len(v)) + v
    head += b"\0"
    line = sum(w * SIZE[chans[n][0]] for n in names)
    first = len(head) + 8 * h
    table = b"".join(struct.pack("<Q", first + k * (8 + line)) for k in range(h))
    body = b""
    for y in range(h):
        body += struct.pack("<ii", y0 + y, line)
        for n in names:
            t, vals = chans[n]
            row = vals[y * w:(y + 1) * w]
            if t == HALF:
                row = [max(-65504.0, min(65504.0, r)) if math.isfinite(r) else r for r in row]
            body += struct.pack("<%d%s" % (w, FMT[t]), *row)
    open(path, "wb").write(head + table + body)


def set_attr(attrs, name, typ, value):
    v = struct.pack("<i", int(value)) if typ == "int" else value.encode()
    for a in attrs:
        if a[0] == name:
            a[1], a[2] = typ, v
            return
    attrs.insert(len(attrs), [name, typ, v])


def retype(chans, name, typ):
    t, vals = chans[name]
    if typ == "half":
        chans[name] = [HALF, [float(x) for x in vals]]
    else:  # the float's bytes read as unsigned ints
        chans[name] = [UINT, list(struct.unpack("<%dI" % len(vals), struct.pack("<%df" % len(vals), *vals)))]


def move_window(attrs, dx, dy):
    for a in attrs:
        if a[0] == "dataWindow":
            x0, y0, x1, y1 = struct.unpack("<4i", a[2])
            a[2] = struct.pack("<4i", x0 + dx, y0 + dy, x1 + dx, y1 + dy)


def mutate(src, dst, seed):
    rng = random.Random(seed)
    kind = rng.randrange(6)
    if kind == 5:  # raw bytes: flips, truncation, a run of 0xff
        data = bytearray(open(src, "rb").read())
        for _ in range(rng.randint(1, 8)):
            op = rng.randrange(3)
            i = rng.randrange(len(data))
            if op == 0:
                data[i] ^= 1 << rng.randrange(8)
            elif op == 1:
                data = data[:i]
                break
            else:
                data[i:i + 4] = b"\xff\xff\xff\xff"
        open(dst, "wb").write(bytes(data))
        return
    attrs, chans = read(src)
    names = sorted(chans)
    if kind == 0:  # values: NaN, Inf, negative, huge, fractional, 0
        for _ in range(rng.randint(1, 4)):
            n = rng.choice(names)
            vals = chans[n][1]
            if chans[n][0] == UINT:
                continue
            vals[rng.randrange(len(vals))] = rng.choice(
                [math.nan, math.inf, -math.inf, -1.0, 1e30, 0.5, 0.0, 3.0e38, -1e-30, 1e8])
    elif kind == 1:
        retype(chans, rng.choice(names), rng.choice(["half", "uint"]))
    elif kind == 2:
        set_attr(attrs, "gonio:spp", "int", rng.choice([0, -1, 1, 2, 3, 7, 9, 15, 17, 2 ** 31 - 1, 10 ** 6]))
    elif kind == 3:
        move_window(attrs, rng.randint(-40, 40), rng.randint(-40, 40))
    else:  # a channel removed or one added
        if rng.randrange(2) and len(names) > 1:
            del chans[rng.choice(names)]
        else:
            w = len(chans[names[0]][1])
            chans[rng.choice(["sum.X", "sum.N", "variance.R", "sum2.R", "Z"])] = [FLOAT, [rng.random()] * w]
    write(dst, attrs, chans)


def main(argv):
    cmd = argv[1] if len(argv) > 1 else ""
    if cmd == "nonfinite" and len(argv) == 3:
        _, chans = read(argv[2])
        print(sum(1 for t, v in chans.values() if t != UINT for x in v if not math.isfinite(x)))
        return 0
    if cmd == "mutate" and len(argv) == 5:
        mutate(argv[2], argv[3], int(argv[4]))
        return 0
    if len(argv) < 4:
        print(__doc__, file=sys.stderr)
        return 2
    attrs, chans = read(argv[2])
    if cmd == "poke" and len(argv) == 8:
        w = struct.unpack("<4i", dict((n, v) for n, t, v in attrs)["dataWindow"])
        width = w[2] - w[0] + 1
        chans[argv[4]][1][int(argv[6]) * width + int(argv[5])] = float(argv[7])
    elif cmd == "retype" and len(argv) == 6:
        retype(chans, argv[4], argv[5])
    elif cmd == "attr" and len(argv) == 7:
        set_attr(attrs, argv[4], argv[5], argv[6])
    elif cmd == "window" and len(argv) == 6:
        move_window(attrs, int(argv[4]), int(argv[5]))
    else:
        print(__doc__, file=sys.stderr)
        return 2
    write(argv[3], attrs, chans)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
