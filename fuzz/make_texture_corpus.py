#!/usr/bin/env python3
"""Writes fuzz_texture's seed corpus (fuzz/corpus_textures/): small images in the two formats glTF
allows and the loader reads (gltf_image.cpp refuses stb_image's others). PNG in each colour type and
bit depth, palette with tRNS, every row filter, Adam7 interlacing (the standard library's zlib);
baseline JPEG (4:2:0 and 4:4:4, colour and grey) through Debian's libstb (stb_image_write, via
ctypes; skipped with a note when libstb.so.0 is missing). Usage: fuzz/make_texture_corpus.py [OUT_DIR]"""
import ctypes, ctypes.util, os, struct, sys, zlib

here = os.path.dirname(os.path.abspath(__file__))
out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "corpus_textures")


def pixels(w, h, n):
    """w*h pixels of n 8-bit channels: a gradient with some structure, so every channel varies."""
    return bytes((x * 37 + y * 11 + c * 80) % 256 for y in range(h) for x in range(w) for c in range(n))


def png_chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def filtered(row, prev, bpp, kind):
    """One PNG row under filter type kind (0 none, 1 sub, 2 up, 3 average, 4 Paeth)."""
    out = bytearray()
    for i, v in enumerate(row):
        a = row[i - bpp] if i >= bpp else 0
        b = prev[i]
        c = prev[i - bpp] if i >= bpp else 0
        if kind == 1: p = a
        elif kind == 2: p = b
        elif kind == 3: p = (a + b) // 2
        elif kind == 4:
            pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
            p = a if pa <= pb and pa <= pc else b if pb <= pc else c
        else: p = 0
        out.append((v - p) % 256)
    return bytes([kind]) + bytes(out)


def png(w, h, colour=6, depth=8, palette=None, trns=None, interlace=False):
    """A PNG; the filter type cycles 0..4 over the rows. Samples come from pixels() (masked to depth)."""
    channels = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}[colour]
    bpp_bits = channels * depth
    bpp = max(1, bpp_bits // 8)
    src = pixels(w, h, channels * (2 if depth == 16 else 1))

    def sample_row(xs, y):
        bits, value, nbits = bytearray(), 0, 0
        for x in xs:
            for c in range(channels):
                if depth == 16:
                    i = ((y * w + x) * channels + c) * 2
                    bits += src[i:i + 2]
                    continue
                v = src[(y * w + x) * channels + c] % (1 << depth)
                if colour == 3: v %= len(palette) // 3
                value, nbits = (value << depth) | v, nbits + depth
                while nbits >= 8:
                    nbits -= 8
                    bits.append((value >> nbits) & 255)
        if nbits: bits.append((value << (8 - nbits)) & 255)
        return bytes(bits)

    passes = ([(0, 0, 8, 8), (4, 0, 8, 8), (0, 4, 4, 8), (2, 0, 4, 4), (0, 2, 2, 4), (1, 0, 2, 2), (0, 1, 1, 2)]
              if interlace else [(0, 0, 1, 1)])
    raw, k = b"", 0
    for x0, y0, dx, dy in passes:
        xs = list(range(x0, w, dx))
        if not xs: continue
        prev = None
        for y in range(y0, h, dy):
            row = sample_row(xs, y)
            prev = prev or bytes(len(row))
            raw += filtered(row, prev, bpp, k % 5)
            prev, k = row, k + 1
    body = png_chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, depth, colour, 0, 0, int(interlace)))
    if palette: body += png_chunk(b"PLTE", palette)
    if trns: body += png_chunk(b"tRNS", trns)
    return b"\x89PNG\r\n\x1a\n" + body + png_chunk(b"IDAT", zlib.compress(raw, 9)) + png_chunk(b"IEND", b"")


def stb_writer():
    """stb_image_write from Debian's libstb: the encoded bytes of one call, through its *_to_func."""
    try:
        lib = ctypes.CDLL(ctypes.util.find_library("stb") or "libstb.so.0")
    except OSError:
        return None
    callback = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_int)

    def write(kind, w, h, n, data, *extra):
        chunks = []
        sink = callback(lambda _ctx, p, size: chunks.append(ctypes.string_at(p, size)))
        fn = getattr(lib, "stbi_write_%s_to_func" % kind)
        if not fn(sink, None, w, h, n, data, *extra): sys.exit("stbi_write_%s failed" % kind)
        return b"".join(chunks)

    return write


def write(name, data):
    with open(os.path.join(out, name), "wb") as f:
        f.write(data)


if __name__ == "__main__":
    os.makedirs(out, exist_ok=True)
    write("rgba_4x4.png", png(4, 4))
    write("rgb_5x3.png", png(5, 3, colour=2))
    write("grey_3x5.png", png(3, 5, colour=0))
    write("grey_alpha_4x2.png", png(4, 2, colour=4))
    write("grey_1bit_9x2.png", png(9, 2, colour=0, depth=1))
    write("rgb16_3x3.png", png(3, 3, colour=2, depth=16))
    write("palette_4bit_trns_5x4.png", png(5, 4, colour=3, depth=4, palette=bytes(range(0, 48)), trns=b"\0\x80\xff"))
    write("rgba_adam7_9x9.png", png(9, 9, interlace=True))
    stb = stb_writer()
    if stb is None:
        print("make_texture_corpus.py: libstb.so.0 not found; JPEG seeds not written", file=sys.stderr)
        sys.exit(0)
    write("rgb_8x8_q75_420.jpg", stb("jpg", 8, 8, 3, pixels(8, 8, 3), 75))
    write("rgb_16x8_q95_444.jpg", stb("jpg", 16, 8, 3, pixels(16, 8, 3), 95))
    write("grey_9x7.jpg", stb("jpg", 9, 7, 1, pixels(9, 7, 1), 80))
