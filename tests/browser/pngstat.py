#!/usr/bin/env python3
"""pngstat.py FILE.png: prints "width height covered colours" for an 8-bit
PNG: covered is the share of pixels that differ from the top-left one (the
page's background), colours the number of distinct pixel values (counted up
to 100000). The standard library only (zlib), so the browser test needs no
imaging package. Exit status 2 for a file that is not such a PNG."""
import struct
import sys
import zlib


def decode(path):
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("not a PNG")
    pos, idat, head = 8, [], None
    while pos + 8 <= len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            head = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat.append(body)
        elif kind == b"IEND":
            break
        pos += 12 + length
    if head is None:
        raise ValueError("no IHDR")
    width, height, depth, ctype, _, _, interlace = head
    channels = {0: 1, 2: 3, 4: 2, 6: 4}.get(ctype)
    if depth != 8 or channels is None or interlace:
        raise ValueError("only 8-bit, non-palette, non-interlaced PNGs are read")
    raw = zlib.decompress(b"".join(idat))
    stride = width * channels
    rows, prev = [], bytearray(stride)
    for y in range(height):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b = prev[i]
            c = prev[i - channels] if i >= channels else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(line))
        prev = line
    return width, height, channels, rows


def main():
    try:
        width, height, ch, rows = decode(sys.argv[1])
    except (OSError, ValueError, zlib.error, struct.error, IndexError) as e:
        print("pngstat: %s: %s" % (sys.argv[1], e), file=sys.stderr)
        return 2
    bg = rows[0][:ch]
    covered, colours = 0, set()
    for r in rows:
        for x in range(0, width * ch, ch):
            px = r[x:x + ch]
            if px != bg:
                covered += 1
            if len(colours) < 100000:
                colours.add(px)
    print(width, height, "%.6f" % (covered / float(width * height)), len(colours))
    return 0


if __name__ == "__main__":
    sys.exit(main())
