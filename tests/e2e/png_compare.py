#!/usr/bin/env python3
"""Compares two 8-bit sRGB PNGs by their means in linear light, whole and in an 8x8 grid of blocks
(pure Python: the test machines have no imaging modules).
Usage: png_compare.py A.png B.png MAX_MEAN_REL MAX_BLOCK_REL MIN_MEAN [--scale S --write OUT.png]
Exit 0 when both images have the same size, A's mean sRGB level is at least MIN_MEAN (not black),
the linear means differ by at most MAX_MEAN_REL of B's, and every block's linear mean by at most
MAX_BLOCK_REL of B's (blocks darker than 1 % of B's mean are compared against 1 % of it).
With --scale S --write OUT.png it instead writes B.png with its linear values times S (the test's
proof that a wrongly scaled image fails)."""
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


def to_linear(level):
    c = level / 255.0
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


def to_srgb_level(v):
    v = min(max(v, 0.0), 1.0)
    c = v * 12.92 if v <= 0.0031308 else 1.055 * v ** (1 / 2.4) - 0.055
    return int(round(c * 255))


LINEAR = [to_linear(level) for level in range(256)]


def block_means(width, height, rows, grid=8):
    """Linear-light block means (mean of the three channels), and the mean sRGB level."""
    sums = [[0.0] * grid for _ in range(grid)]
    counts = [[0] * grid for _ in range(grid)]
    level = 0.0
    for y, line in enumerate(rows):
        by = y * grid // height
        for x in range(width):
            bx = x * grid // width
            sums[by][bx] += (LINEAR[line[3 * x]] + LINEAR[line[3 * x + 1]] + LINEAR[line[3 * x + 2]]) / 3.0
            counts[by][bx] += 1
            level += (line[3 * x] + line[3 * x + 1] + line[3 * x + 2]) / 3.0
    return [[sums[j][i] / max(1, counts[j][i]) for i in range(grid)] for j in range(grid)], level / (width * height)


def write_png(path, width, height, rows):
    raw = b"".join(b"\x00" + bytes(line) for line in rows)
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)) +
                chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


if "--scale" in sys.argv:
    scale, out = float(sys.argv[sys.argv.index("--scale") + 1]), sys.argv[sys.argv.index("--write") + 1]
    w, h, rows = read_png(sys.argv[2])
    write_png(out, w, h, [[to_srgb_level(LINEAR[v] * scale) for v in line] for line in rows])
    sys.exit(0)

a_path, b_path = sys.argv[1], sys.argv[2]
max_mean, max_block, min_mean = float(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])
wa, ha, ra = read_png(a_path)
wb, hb, rb = read_png(b_path)
if (wa, ha) != (wb, hb):
    sys.exit(f"sizes differ: {wa}x{ha} and {wb}x{hb}")
(ma, level_a), (mb, _) = block_means(wa, ha, ra), block_means(wb, hb, rb)
mean_a, mean_b = sum(map(sum, ma)) / 64, sum(map(sum, mb)) / 64
floor = 0.01 * mean_b
worst = max(abs(ma[j][i] - mb[j][i]) / max(mb[j][i], floor) for j in range(8) for i in range(8))
rel = abs(mean_a - mean_b) / max(mean_b, 1e-12)
print(f"linear mean {mean_a:.4f} vs {mean_b:.4f} ({100 * rel:.1f} % apart), worst block {100 * worst:.1f} % apart")
if level_a < min_mean:
    sys.exit(f"{a_path} is black (mean level {level_a:.1f} < {min_mean})")
if rel > max_mean or worst > max_block:
    sys.exit("the images differ more than allowed")
