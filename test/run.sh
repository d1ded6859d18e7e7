#!/bin/sh
# Runs every test program in $1/test, the examples (smoke tests, images into a scratch folder),
# the C++ header compile and the symbol check; prints "tests: N passed, M failed" last.
build=$1; cxx=${2:-c++}
passed=0; failed=0
scratch=$(mktemp -d 2>/dev/null || echo "$build/scratch"); mkdir -p "$scratch"
for t in "$build"/test/test_*; do
  [ -x "$t" ] || continue
  echo "== $t"
  "$t" > "$scratch/log" 2>&1; rc=$?
  cat "$scratch/log"
  line=$(grep '^RESULT ' "$scratch/log" | tail -n 1)
  if [ -z "$line" ]; then failed=$((failed + 1)); echo "FAIL $t crashed or printed no RESULT (exit $rc)"; continue; fi
  n=$(echo "$line" | sed 's/.*tests=\([0-9]*\).*/\1/'); f=$(echo "$line" | sed 's/.*failed=\([0-9]*\).*/\1/')
  passed=$((passed + n - f)); failed=$((failed + f))
  if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then failed=$((failed + 1)); echo "FAIL $t exit $rc"; fi
done
# the library's calls on threads (hfvis.h, "Threads"), built with -pthread
if [ -x "$build/thread/thread_test" ]; then
  "$build/thread/thread_test" > "$scratch/log" 2>&1; rc=$?
  if [ "$rc" -eq 0 ] && grep -q '^RESULT .*failed=0' "$scratch/log"; then passed=$((passed + 1)); echo "ok   thread_test: $(tail -n 1 "$scratch/log")"
  else failed=$((failed + 1)); cat "$scratch/log"; echo "FAIL thread_test (exit $rc)"; fi
fi
for e in "$build"/examples/*; do
  [ -x "$e" ] || continue
  if "$e" "$scratch" > "$scratch/log" 2>&1; then passed=$((passed + 1)); echo "ok   example $(basename "$e")"
  else failed=$((failed + 1)); cat "$scratch/log"; echo "FAIL example $(basename "$e")"; fi
done
# The examples' PNGs through a real decoder, and a copy with its zlib header byte (offset 41)
# overwritten that must be rejected; SKIP (exit 77) without python3 and ImageMagick.
sh test/png_check.sh "$scratch" > "$scratch/log" 2>&1; rc=$?
if [ "$rc" -eq 77 ]; then cat "$scratch/log"
elif [ "$rc" -eq 0 ] && mkdir -p "$scratch/bad" && cp "$(ls "$scratch"/*.png | head -n 1)" "$scratch/bad/x.png" &&
     printf X | dd of="$scratch/bad/x.png" bs=1 seek=41 conv=notrunc 2>/dev/null &&
     ! sh test/png_check.sh "$scratch/bad" > /dev/null 2>&1; then
  passed=$((passed + 1)); echo "ok   png check: $(tail -n 1 "$scratch/log" | sed "s/^png_check: //"), a corrupted copy rejected"
else failed=$((failed + 1)); cat "$scratch/log"; echo "FAIL png check"; fi
if [ -f test/cli_test.sh ] && [ -x "$build/hfvis" ]; then
  if sh test/cli_test.sh "$build/hfvis" "$scratch" > "$scratch/log" 2>&1; then passed=$((passed + 1)); echo "ok   cli"
  else failed=$((failed + 1)); cat "$scratch/log"; echo "FAIL cli"; fi
fi
# tiles: --window pieces and hfvis mosaic (the search-radius checks print SKIP while the library
# ignores max_distance)
if [ -x "$build/hfvis" ]; then
  if sh test/tiles_cli_test.sh "$build/hfvis" "$scratch" > "$scratch/log" 2>&1; then passed=$((passed + 1))
    grep '^SKIP' "$scratch/log"; echo "ok   tiles cli: $(tail -n 1 "$scratch/log")"
  else failed=$((failed + 1)); cat "$scratch/log"; echo "FAIL tiles cli"; fi
fi
# GIS rasters through the tool (GDAL interop when installed, else a printed SKIP)
if [ -x "$build/hfvis" ]; then
  if sh test/raster_cli_test.sh "$build/hfvis" "$scratch" > "$scratch/log" 2>&1; then passed=$((passed + 1))
    grep '^SKIP' "$scratch/log"; echo "ok   raster cli: $(tail -n 1 "$scratch/log")"
  else failed=$((failed + 1)); cat "$scratch/log"; echo "FAIL raster cli"; fi
fi
if $cxx -std=c++11 -Wall -Wextra -Werror -pedantic -fsyntax-only -I. test/cxx_header.cpp; then
  passed=$((passed + 1)); echo "ok   cxx header"; else failed=$((failed + 1)); echo "FAIL cxx header"; fi
# install (make install/uninstall, pkg-config, a user program; exit 77 = skipped without pkg-config)
# and vendor (the four library files alone, plain $CC -std=c99): one pass/fail each.
sh test/install_test.sh "$build" "$scratch" > "$scratch/log" 2>&1; rc=$?
if [ "$rc" -eq 0 ]; then passed=$((passed + 1)); tail -n 1 "$scratch/log"
elif [ "$rc" -eq 77 ]; then cat "$scratch/log"
else failed=$((failed + 1)); cat "$scratch/log"; echo "FAIL install"; fi
if sh test/vendor_test.sh "$scratch" > "$scratch/log" 2>&1; then passed=$((passed + 1)); tail -n 1 "$scratch/log"
else failed=$((failed + 1)); cat "$scratch/log"; echo "FAIL vendor"; fi
bad=$(nm -g --defined-only "$build/libhfvis.a" | awk 'NF==3 && $2 ~ /[TDBRC]/ {print $3}' | grep -v '^hfvis_')
if [ -z "$bad" ]; then passed=$((passed + 1)); echo "ok   symbols"; else failed=$((failed + 1)); echo "FAIL symbols: $bad"; fi
rm -rf "$scratch"
echo "tests: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
