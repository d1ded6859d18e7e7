#!/bin/sh
# Runs every test program in $1/test, the examples (smoke tests, images into a scratch folder),
# the C++ header compile and the symbol check; prints "tests: N passed, M failed" last.
# The steps are independent and run $TEST_JOBS at a time (default 2; 1 = one after the other):
# each writes its lines to its own file, and the lines are printed in the steps' order.
build=$1; cxx=${2:-c++}; jobs=${TEST_JOBS:-2}
case "$jobs" in '' | *[!0-9]* | 0) echo "run.sh: TEST_JOBS must be a positive integer, got '$jobs'"; exit 2 ;; esac
scratch=$(mktemp -d 2>/dev/null || echo "$build/scratch"); mkdir -p "$scratch"

# ---- the steps, in the order their lines are printed ------------------------------------
nsteps=0
add() { nsteps=$((nsteps + 1)); eval "step_$nsteps=\$1"; }
for t in "$build"/test/test_*; do [ -x "$t" ] && add "prog $t"; done
add thread; add examples; add cli; add tiles; add raster; add cxx; add install; add vendor; add symbols

# run_step I: runs step I with its own log and scratch folder; prints its lines and writes
# "PASSED FAILED" to $scratch/res.I.
run_step() {
  i=$1; log=$scratch/log.$i; p=0; f=0
  eval "s=\$step_$i"
  case "$s" in
  "prog "*)
    t=${s#prog }
    echo "== $t"
    "$t" > "$log" 2>&1; rc=$?
    cat "$log"
    line=$(grep '^RESULT ' "$log" | tail -n 1)
    if [ -z "$line" ]; then f=1; echo "FAIL $t crashed or printed no RESULT (exit $rc)"
    else
      n=$(echo "$line" | sed 's/.*tests=\([0-9]*\).*/\1/'); f=$(echo "$line" | sed 's/.*failed=\([0-9]*\).*/\1/')
      p=$((n - f))
      if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then f=1; echo "FAIL $t exit $rc"; fi
    fi ;;
  thread) # the library's calls on threads (hfvis.h, "Threads"), built with -pthread
    if [ -x "$build/thread/thread_test" ]; then
      "$build/thread/thread_test" > "$log" 2>&1; rc=$?
      if [ "$rc" -eq 0 ] && grep -q '^RESULT .*failed=0' "$log"; then p=1; echo "ok   thread_test: $(tail -n 1 "$log")"
      else f=1; cat "$log"; echo "FAIL thread_test (exit $rc)"; fi
    fi ;;
  examples)
    ex=$scratch/examples; mkdir -p "$ex"
    for e in "$build"/examples/*; do
      [ -x "$e" ] || continue
      if "$e" "$ex" > "$log" 2>&1; then p=$((p + 1)); echo "ok   example $(basename "$e")"
      else f=$((f + 1)); cat "$log"; echo "FAIL example $(basename "$e")"; fi
    done
    # The examples' PNGs through a real decoder, and a copy with its zlib header byte (offset 41)
    # overwritten that must be rejected; SKIP (exit 77) without python3 and ImageMagick.
    sh test/png_check.sh "$ex" > "$log" 2>&1; rc=$?
    if [ "$rc" -eq 77 ]; then cat "$log"
    elif [ "$rc" -eq 0 ] && mkdir -p "$ex/bad" && cp "$(ls "$ex"/*.png | head -n 1)" "$ex/bad/x.png" &&
         printf X | dd of="$ex/bad/x.png" bs=1 seek=41 conv=notrunc 2>/dev/null &&
         ! sh test/png_check.sh "$ex/bad" > /dev/null 2>&1; then
      p=$((p + 1)); echo "ok   png check: $(tail -n 1 "$log" | sed "s/^png_check: //"), a corrupted copy rejected"
    else f=$((f + 1)); cat "$log"; echo "FAIL png check"; fi ;;
  cli)
    if [ -f test/cli_test.sh ] && [ -x "$build/hfvis" ]; then
      if sh test/cli_test.sh "$build/hfvis" "$scratch" > "$log" 2>&1; then p=1; echo "ok   cli"
      else f=1; cat "$log"; echo "FAIL cli"; fi
    fi ;;
  tiles) # --window pieces and hfvis mosaic (the search-radius checks print SKIP while the
         # library ignores max_distance)
    if [ -x "$build/hfvis" ]; then
      if sh test/tiles_cli_test.sh "$build/hfvis" "$scratch" > "$log" 2>&1; then p=1
        grep '^SKIP' "$log"; echo "ok   tiles cli: $(tail -n 1 "$log")"
      else f=1; cat "$log"; echo "FAIL tiles cli"; fi
    fi ;;
  raster) # GIS rasters through the tool (GDAL interop when installed, else a printed SKIP)
    if [ -x "$build/hfvis" ]; then
      if sh test/raster_cli_test.sh "$build/hfvis" "$scratch" > "$log" 2>&1; then p=1
        grep '^SKIP' "$log"; echo "ok   raster cli: $(tail -n 1 "$log")"
      else f=1; cat "$log"; echo "FAIL raster cli"; fi
    fi ;;
  cxx)
    if $cxx -std=c++11 -Wall -Wextra -Werror -pedantic -fsyntax-only -I. test/cxx_header.cpp; then
      p=1; echo "ok   cxx header"; else f=1; echo "FAIL cxx header"; fi ;;
  install) # make install/uninstall, pkg-config, a user program; exit 77 = skipped without pkg-config
    sh test/install_test.sh "$build" "$scratch" > "$log" 2>&1; rc=$?
    if [ "$rc" -eq 0 ]; then p=1; tail -n 1 "$log"
    elif [ "$rc" -eq 77 ]; then cat "$log"
    else f=1; cat "$log"; echo "FAIL install"; fi ;;
  vendor) # the four library files alone, plain $CC -std=c99
    if sh test/vendor_test.sh "$scratch" > "$log" 2>&1; then p=1; tail -n 1 "$log"
    else f=1; cat "$log"; echo "FAIL vendor"; fi ;;
  symbols)
    bad=$(nm -g --defined-only "$build/libhfvis.a" | awk 'NF==3 && $2 ~ /[TDBRC]/ {print $3}' | grep -v '^hfvis_')
    if [ -z "$bad" ]; then p=1; echo "ok   symbols"; else f=1; echo "FAIL symbols: $bad"; fi ;;
  esac
  echo "$p $f" > "$scratch/res.$i"
}

# ---- $jobs workers take the steps, longest first (measured CPU time), by an atomic mkdir ----
order=
for k in cli tiles test_solar test_ssao test_lk test_visfield vendor test_hfvis examples raster test_ffao; do
  i=1
  while [ "$i" -le "$nsteps" ]; do
    eval "s=\$step_$i"
    case "$s" in "$k" | "prog "*/"$k") order="$order $i" ;; esac
    i=$((i + 1))
  done
done
i=1; while [ "$i" -le "$nsteps" ]; do case " $order " in *" $i "*) ;; *) order="$order $i" ;; esac; i=$((i + 1)); done
worker() {
  for i in $order; do
    mkdir "$scratch/claim.$i" 2>/dev/null || continue
    run_step "$i" > "$scratch/out.$i" 2>&1
    : > "$scratch/done.$i"
  done
}
pids=; w=0
while [ "$w" -lt "$jobs" ]; do worker & pids="$pids $!"; w=$((w + 1)); done

# ---- the steps' lines in order, each as soon as it and those before it are done ----------
passed=0; failed=0; i=1
while [ "$i" -le "$nsteps" ]; do
  while [ ! -e "$scratch/done.$i" ]; do
    alive=0; for pid in $pids; do kill -0 "$pid" 2>/dev/null && alive=1; done
    [ "$alive" -eq 1 ] || [ -e "$scratch/done.$i" ] || break
    sleep 1
  done
  if [ -e "$scratch/done.$i" ] && read -r p f < "$scratch/res.$i"; then
    cat "$scratch/out.$i"; passed=$((passed + p)); failed=$((failed + f))
  else eval "echo \"FAIL step \$step_$i did not finish\""; failed=$((failed + 1)); fi
  i=$((i + 1))
done
wait
rm -rf "$scratch"
echo "tests: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
