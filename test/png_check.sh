#!/bin/sh
# png_check.sh DIR - validates every *.png in DIR with real decoders: python3's zlib (every chunk
# CRC, IHDR first and IEND last, the zlib stream inflated, its Adler-32, exactly
# H * (1 + row bytes) bytes, valid filter types) and ImageMagick's identify -regard-warnings,
# whichever is present. Exit 0: all valid; 1: a file is invalid or DIR has no PNG; 77: SKIP,
# neither tool exists.
dir=${1:?usage: png_check.sh DIR}
py=; im=
if command -v python3 >/dev/null 2>&1 && python3 -c 'import zlib' >/dev/null 2>&1; then py=python3; fi
if command -v magick >/dev/null 2>&1; then im="magick identify"
elif command -v identify >/dev/null 2>&1; then im=identify; fi
if [ -z "$py" ] && [ -z "$im" ]; then
  echo "SKIP png check: neither python3 nor ImageMagick identify found"
  exit 77
fi
set -- "$dir"/*.png
if [ ! -f "$1" ]; then echo "png_check: no PNG files in $dir"; exit 1; fi
bad=0; tools=
if [ -n "$py" ]; then
  tools="python3 zlib"
  "$py" - "$@" <<'EOF' || bad=1
import struct, sys, zlib

# PNG spec (ISO/IEC 15948) Table 11.1: allowed bit depths per colour type, and channels.
DEPTHS = {0: (1, 2, 4, 8, 16), 2: (8, 16), 3: (1, 2, 4, 8), 4: (8, 16), 6: (8, 16)}
CHANNELS = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}

def check(path):
    with open(path, 'rb') as f:
        b = f.read()
    if b[:8] != b'\x89PNG\r\n\x1a\n':
        return 'bad signature'
    pos, chunks = 8, []
    while pos < len(b):
        if pos + 12 > len(b):
            return 'truncated chunk at byte %d' % pos
        n, t = struct.unpack('>I4s', b[pos:pos + 8])
        if n > 0x7fffffff or pos + 12 + n > len(b):
            return 'chunk length %d at byte %d runs past the end' % (n, pos)
        data = b[pos + 8:pos + 8 + n]
        crc, = struct.unpack('>I', b[pos + 8 + n:pos + 12 + n])
        if zlib.crc32(t + data) & 0xffffffff != crc:
            return 'CRC mismatch in %r at byte %d' % (t, pos)
        if not t.isalpha():
            return 'bad chunk type %r' % t
        chunks.append((t, data))
        pos += 12 + n
        if t == b'IEND':
            break
    if pos != len(b):
        return '%d bytes after IEND' % (len(b) - pos)
    if not chunks or chunks[0][0] != b'IHDR' or len(chunks[0][1]) != 13:
        return 'IHDR is not the first chunk'
    if chunks[-1][0] != b'IEND' or chunks[-1][1]:
        return 'IEND is not the last chunk'
    w, h, depth, ctype, comp, filt, inter = struct.unpack('>IIBBBBB', chunks[0][1])
    if not (0 < w < 2**31 and 0 < h < 2**31) or depth not in DEPTHS.get(ctype, ()) or comp or filt:
        return 'bad IHDR %dx%d depth %d colour type %d' % (w, h, depth, ctype)
    if inter:
        return 'interlaced: not checked'
    idat = [i for i, c in enumerate(chunks) if c[0] == b'IDAT']
    if not idat or idat != list(range(idat[0], idat[-1] + 1)):
        return 'IDAT chunks missing or not consecutive'
    z = b''.join(chunks[i][1] for i in idat)
    d = zlib.decompressobj()
    try:
        raw = d.decompress(z) + d.flush()
    except zlib.error as e:
        return 'zlib: %s' % e
    if not d.eof or d.unused_data:
        return 'zlib stream incomplete or followed by %d bytes' % len(d.unused_data)
    if struct.unpack('>I', z[-4:])[0] != zlib.adler32(raw) & 0xffffffff:
        return 'Adler-32 mismatch'
    row = (w * CHANNELS[ctype] * depth + 7) // 8
    if len(raw) != h * (1 + row):
        return 'inflated %d bytes, want %d x (1 + %d) = %d' % (len(raw), h, row, h * (1 + row))
    for y in range(h):
        if raw[y * (1 + row)] > 4:
            return 'row %d has filter type %d' % (y, raw[y * (1 + row)])
    return None

bad = 0
for p in sys.argv[1:]:
    why = check(p)
    if why:
        print('png_check: %s: %s' % (p, why))
        bad += 1
sys.exit(1 if bad else 0)
EOF
fi
if [ -n "$im" ]; then
  tools="${tools:+$tools and }ImageMagick"
  for f in "$@"; do
    if ! $im -regard-warnings "$f" >/dev/null 2>&1; then echo "png_check: $f: rejected by $im"; bad=1; fi
  done
fi
if [ "$bad" -ne 0 ]; then exit 1; fi
echo "png_check: $# PNG files valid ($tools)"
