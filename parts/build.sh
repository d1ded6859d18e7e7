#!/bin/sh
# sh parts/build.sh NAME [DEP ...]   (run from anywhere)
# Builds parts/test_NAME.c against hfvis.c + voxel.c with the parts DEP... and NAME pasted after
# voxel.c's core in the canonical order (mesh raster bvh vox cons iv), exactly as the final
# merge will, and with their parts/*_decl.h pasted before the end of hfvis.h. Then runs it.
# SAN=1: ASan+UBSan build. BENCH=1: build parts/bench_NAME.c (a main of its own) at -O2 instead.
# Extra compiler flags: CFLAGS_EXTRA.
set -e
cd "$(dirname "$0")/.."
name=$1; shift
order="mesh raster bvh vox cons iv vf volgi"
want=" $name $* "
out=build/dev/$name${SAN:+_san}${BENCH:+_bench}
mkdir -p "$out"
cp voxel.c "$out/voxel_dev.c.tmp"
decls=""
for p in $order; do
  [ -f "parts/$p.c" ] || continue # already merged into voxel.c
  case "$want" in *" $p "*)
    printf '\n/* ---- parts/%s.c ---- */\n' "$p" >> "$out/voxel_dev.c.tmp"
    cat "parts/$p.c" >> "$out/voxel_dev.c.tmp"
    [ -f "parts/${p}_decl.h" ] && decls="$decls parts/${p}_decl.h";;
  esac
done
mv "$out/voxel_dev.c.tmp" "$out/voxel_dev.c"
WARN="-std=c99 -pedantic -Wall -Wextra -Wshadow -Wstrict-prototypes -Wmissing-prototypes -Wundef -Wvla -Wcast-qual -Wdouble-promotion -Wfloat-conversion -Wimplicit-fallthrough -Wmissing-field-initializers -ffp-contract=off -Werror"
if [ -n "$SAN" ]; then OPT="-O1 -g -DHFVIS_ENABLE_ASSERTS -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer"
else OPT="-O2 -g -DHFVIS_ENABLE_ASSERTS"; fi
if [ -n "$BENCH" ]; then OPT="-O2"; src=parts/bench_$name.c; else src=parts/test_$name.c; fi
# hfvis.c parts (pasted at the end of hfvis.c): gi2
cp hfvis.c "$out/hfvis.c.tmp"
for p in gi2; do
  [ -f "parts/$p.c" ] || continue # already merged into hfvis.c
  case "$want" in *" $p "*)
    printf '\n/* ---- parts/%s.c ---- */\n' "$p" >> "$out/hfvis.c.tmp"
    cat "parts/$p.c" >> "$out/hfvis.c.tmp"
    [ -f "parts/${p}_decl.h" ] && decls="$decls parts/${p}_decl.h";;
  esac
done
mv "$out/hfvis.c.tmp" "$out/hfvis.c"
# ssao.c part: parts/ssao.c is the whole new ssao.c (used instead of ssao.c when "ssao" is listed)
case " $name $* " in *" ssao "*) [ -f parts/ssao.c ] && cp parts/ssao.c "$out/ssao_dev.c" || cp ssao.c "$out/ssao_dev.c"
  [ -f parts/ssao_decl.h ] && decls="$decls parts/ssao_decl.h";;
*) cp ssao.c "$out/ssao_dev.c";; esac
# ssao.c appended parts: ssaob (P4 far-field AO), lk (Laine-Karras)
for p in ssaob lk; do
  [ -f "parts/$p.c" ] || continue
  case "$want" in *" $p "*)
    printf '\n/* ---- parts/%s.c ---- */\n' "$p" >> "$out/ssao_dev.c"
    cat "parts/$p.c" >> "$out/ssao_dev.c"
    [ -f "parts/${p}_decl.h" ] && decls="$decls parts/${p}_decl.h";;
  esac
done
# header: everything before the final "#ifdef __cplusplus" + decls + the tail
n=$(grep -n '^#ifdef __cplusplus' hfvis.h | tail -n 1 | cut -d: -f1)
head -n $((n - 1)) hfvis.h > "$out/hfvis.h"
for d in $decls; do cat "$d" >> "$out/hfvis.h"; done
tail -n +"$n" hfvis.h >> "$out/hfvis.h"
${CC:-gcc} $WARN $OPT $CFLAGS_EXTRA -I"$out" -Itest -Iexamples "$src" "$out/hfvis.c" "$out/ssao_dev.c" "$out/voxel_dev.c" -lm -o "$out/prog"
echo "built $out/prog"
"$out/prog"
