#!/bin/sh
# vendor_test.sh - the README's vendoring promise, checked: copy ONLY hfvis.h, hfvis.c, ssao.c and
# voxel.c into an empty folder, compile them with plain `cc -std=c99 -c` (no Makefile, no -D, no
# generated file), then build every example (examples/0*.c, 1*.c) and the hfvis tool against
# them from a second folder holding the example sources with examples/common.h, png_write.h, zio.h, raster_io.h and fields.h copied beside
# them, and run one example into a scratch folder.
# usage: sh test/vendor_test.sh [SCRATCHDIR]   (from the repository root; compiler $CC, default
# cc; extra flags in $VENDOR_CFLAGS, e.g. -O2). Exit 0 = passed, anything else = failed.
dir=${1:-${TMPDIR:-/tmp}}/vendor_test.$$
cc=${CC:-cc}
flags="-std=c99${VENDOR_CFLAGS:+ $VENDOR_CFLAGS}"
[ -f hfvis.h ] && [ -f examples/common.h ] || { echo "vendor: run from the repository root"; exit 2; }
rm -rf "$dir"; mkdir -p "$dir/vendor" "$dir/app" "$dir/out" || exit 1
fail() { echo "FAIL vendor: $1"; rm -rf "$dir"; exit 1; }

cp hfvis.h hfvis.c ssao.c voxel.c "$dir/vendor/" || fail "copy"
cp examples/common.h examples/png_write.h examples/zio.h examples/raster_io.h examples/fields.h examples/0*.c examples/1*.c "$dir/app/" || fail "copy"
mkdir -p "$dir/app/cli" && cp examples/cli/*.c examples/cli/*.h "$dir/app/cli/" || fail "copy" # the tool beside, as in examples/
# shellcheck disable=SC2086 # $flags is a list of flags
(cd "$dir/vendor" && $cc $flags -c hfvis.c && $cc $flags -c ssao.c && $cc $flags -c voxel.c) \
  > "$dir/log" 2>&1 || { cat "$dir/log"; fail "$cc $flags -c hfvis.c ssao.c voxel.c"; }
n=0
for src in "$dir"/app/*.c "$dir"/app/cli/main.c; do # main.c includes the other files of cli/
  prog=${src%.c}
  # shellcheck disable=SC2086
  $cc $flags -I"$dir/vendor" "$src" "$dir/vendor/hfvis.o" "$dir/vendor/ssao.o" "$dir/vendor/voxel.o" -lm -o "$prog" \
    > "$dir/log" 2>&1 || { cat "$dir/log"; fail "$cc $flags $(basename "$src")"; }
  n=$((n + 1))
done
[ "$n" -ge 2 ] || fail "found only $n example sources"
"$dir/app/02_sky_view_factor" "$dir/out" > "$dir/log" 2>&1 || { cat "$dir/log"; fail "02_sky_view_factor did not run"; }
for f in 02_sky_light.pgm 02_sky_view_factor.pgm; do
  [ -s "$dir/out/$f" ] || fail "02_sky_view_factor did not write $f"
done
"$dir/app/cli/main" --help > /dev/null 2>&1 || fail "hfvis --help failed"
rm -rf "$dir"
echo "ok   vendor ($n programs built with $cc $flags from the four library files alone; 02_sky_view_factor ran)"
