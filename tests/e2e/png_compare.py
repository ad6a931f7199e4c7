#!/usr/bin/env python3
"""Compares two 8-bit RGB PNGs by block means (pure Python: the test machines have no imaging
modules). Usage: png_compare.py A.png B.png MAX_MEAN_DIFF MAX_BLOCK_DIFF MIN_MEAN
Exit 0 when both images have the same size, A's mean level is at least MIN_MEAN (not black), the
mean levels differ by at most MAX_MEAN_DIFF, and every 8x8-grid block mean by at most MAX_BLOCK_DIFF."""
import struct, sys, zlib


def read_png(path):
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit(f"{path}: not a PNG")
    pos, idat, width, height = 8, b"", 0, 0
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind, chunk = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + length]
        pos += 12 + length
        if kind == b"IHDR":
            width, height, depth, colour = struct.unpack(">IIBB", chunk[:10])
            if depth != 8 or colour != 2:
                sys.exit(f"{path}: only 8-bit RGB PNGs are compared")
        elif kind == b"IDAT":
            idat += chunk
    raw, stride, bpp = zlib.decompress(idat), width * 3, 3
    rows, previous, p = [], bytearray(stride), 0
    for _ in range(height):
        kind, line = raw[p], bytearray(raw[p + 1:p + 1 + stride])
        p += 1 + stride
        for x in range(stride):  # undo the PNG row filters
            a = line[x - bpp] if x >= bpp else 0
            b, c = previous[x], previous[x - bpp] if x >= bpp else 0
            if kind == 1: line[x] = (line[x] + a) & 255
            elif kind == 2: line[x] = (line[x] + b) & 255
            elif kind == 3: line[x] = (line[x] + (a + b) // 2) & 255
            elif kind == 4:
                e = a + b - c
                pa, pb, pc = abs(e - a), abs(e - b), abs(e - c)
                line[x] = (line[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        previous = line
    return width, height, rows


def block_means(width, height, rows, grid=8):
    sums = [[0.0] * grid for _ in range(grid)]
    counts = [[0] * grid for _ in range(grid)]
    for y, line in enumerate(rows):
        by = y * grid // height
        for x in range(width):
            bx = x * grid // width
            sums[by][bx] += (line[3 * x] + line[3 * x + 1] + line[3 * x + 2]) / 3.0
            counts[by][bx] += 1
    return [[sums[j][i] / max(1, counts[j][i]) for i in range(grid)] for j in range(grid)]


a_path, b_path = sys.argv[1], sys.argv[2]
max_mean, max_block, min_mean = float(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])
wa, ha, ra = read_png(a_path)
wb, hb, rb = read_png(b_path)
if (wa, ha) != (wb, hb):
    sys.exit(f"sizes differ: {wa}x{ha} and {wb}x{hb}")
ma, mb = block_means(wa, ha, ra), block_means(wb, hb, rb)
mean_a, mean_b = sum(map(sum, ma)) / 64, sum(map(sum, mb)) / 64
worst = max(abs(ma[j][i] - mb[j][i]) for j in range(8) for i in range(8))
print(f"mean level {mean_a:.1f} vs {mean_b:.1f}, worst block difference {worst:.1f}")
if mean_a < min_mean:
    sys.exit(f"{a_path} is black (mean level {mean_a:.1f} < {min_mean})")
if abs(mean_a - mean_b) > max_mean or worst > max_block:
    sys.exit("the images differ more than allowed")
