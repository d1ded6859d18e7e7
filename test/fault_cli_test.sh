#!/bin/sh
# fault_cli_test.sh - every output format of the hfvis tool under a failing disk: a file-size
# limit (ulimit -f, with SIGXFSZ at its default action and ignored) and, where strace is
# installed, an injected failure (ENOSPC, EIO) of the write path's system calls: openat, write,
# pwrite64 (a PFM's slices when the run has threads), close, rename (and fsync, fdatasync where
# the tool calls them), at the first, second, middle and last call from the creation of the output's temporary file on.
# Each case runs with OUT absent and with OUT holding older contents. A run that exits 0 must have
# written exactly the good run's files; a run that fails must exit non-zero with exactly one
# stderr line "hfvis...", leave OUT as it was (absent, or its older bytes), leave every other file
# it writes (.hdr, .prj, .tile, the --split files) either as it was or as the good run writes it,
# and leave no temporary file. For a --window piece, the mosaic of the piece beside the other
# pieces must then either refuse or equal the mosaic of the older run: no piece is left with a
# sidecar of another run.
# Last, SIGINT and SIGTERM while a raster and its sidecars are published (strace holds each call).
# The strace part prints "SKIP: strace ..." without strace (or where ptrace is not permitted).
# usage: sh test/fault_cli_test.sh BUILD/hfvis [SCRATCHDIR]
hfvis=$1
[ -n "$hfvis" ] && [ -x "$hfvis" ] || { echo "usage: sh test/fault_cli_test.sh BUILD/hfvis [SCRATCHDIR]"; exit 2; }
hfvis=$(cd "$(dirname "$hfvis")" && pwd)/$(basename "$hfvis")
dir=${2:-${TMPDIR:-/tmp}}/fault_cli_test.$$
rm -rf "$dir"; mkdir -p "$dir/in" || exit 1
trap 'rm -rf "$dir"' EXIT
trap 'exit 130' INT TERM HUP
passed=0; failed=0; runs=0
ok()  { passed=$((passed + 1)); echo "ok   fault $1"; }
bad() { failed=$((failed + 1)); echo "FAIL fault $1"; }

# ---- inputs ----------------------------------------------------------------------------------
in=$dir/in
LC_ALL=C awk 'BEGIN { w = 64; h = 48
  printf "ncols %d\nnrows %d\nxllcorner 500000\nyllcorner 4100000\ncellsize 2\nNODATA_value -9999\n", w, h
  for (y = 0; y < h; y++) { s = ""
    for (x = 0; x < w; x++) { v = int(100 + 30 * sin(x / 5) * cos(y / 7)); if (x == 20) v += 40; s = s " " v }
    print s } }' > "$in/dem.asc"
printf 'PROJCS["WGS 84 / UTM zone 33N",GEOGCS["WGS 84",DATUM["WGS_1984",SPHEROID["WGS 84",6378137,298.257223563]],PRIMEM["Greenwich",0],UNIT["degree",0.0174532925199433]],PROJECTION["Transverse_Mercator"],PARAMETER["central_meridian",15],UNIT["metre",1],AUTHORITY["EPSG","32633"]]\n' > "$in/dem.prj"
# a box beside a tilted square: a binvox with more than one run
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nv 2 0 0\nv 3 1 2\nv 2 2 1\nf 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\nf 9 10 11\n' > "$in/m.obj"
R="--max-distance 40"
for ext in pfm tif; do
  "$hfvis" skyview "$in/dem.asc" --dirs 8 $R --quiet --window 0,0,32,48 -o "$in/a.$ext" &&
  "$hfvis" skyview "$in/dem.asc" --dirs 8 $R --quiet --window 32,0,32,48 -o "$in/b.$ext" &&
  "$hfvis" skyview "$in/dem.asc" --dirs 16 $R --quiet --window 0,0,32,48 -o "$in/a16.$ext" || { bad "setup: pieces"; exit 1; }
  "$hfvis" mosaic "$in/a.$ext" "$in/b.$ext" --quiet -o "$in/mosaic8.$ext" || { bad "setup: mosaic"; exit 1; }
done

# The cases: NAME|OUT|OTHER FILES IT WRITES|ARGUMENTS (OUT as the last -o)|OLDER OUT's ARGUMENTS
# (empty: older contents are a few bytes of text). The pieces' older run is --dirs 8 (the other
# pieces' run); the faulty run is --dirs 16.
cases="pfm|o.pfm||skyview $in/dem.asc --dirs 8 --quiet -o o.pfm|
pgm|o.pgm||skyview $in/dem.asc --dirs 8 --quiet -o o.pgm|
tif|o.tif||skyview $in/dem.asc --dirs 8 --quiet -o o.tif|
asc|o.asc|o.prj|skyview $in/dem.asc --dirs 8 --quiet -o o.asc|
bil|o.bil|o.hdr o.prj|skyview $in/dem.asc --dirs 8 --quiet -o o.bil|
flt|o.flt|o.hdr o.prj|horizon $in/dem.asc --dirs 4 --quiet -o o.flt|
pfm-threads|t.pfm||horizon $in/dem.asc --dirs 4 --threads 2 --quiet -o t.pfm|
hfvs|o.hfvs||skyview $in/dem.asc --dirs 8 --dir-range 0:4 --quiet -o o.hfvs|
binvox|o.binvox||voxelize $in/m.obj --res 24 --quiet -o o.binvox|
raw|o.raw||voxelize $in/m.obj --res 24 --mode solid --open --quiet -o o.raw|
mosaic-pfm|m.pfm||mosaic $in/a.pfm $in/b.pfm --quiet -o m.pfm|
mosaic-tif|m.tif||mosaic $in/a.tif $in/b.tif --quiet -o m.tif|
split|h.pfm|h_000.pfm h_090.pfm h_180.pfm h_270.pfm|horizon $in/dem.asc --dirs 4 --split --quiet -o h.pfm|
piece-pfm|a.pfm|a.pfm.tile|skyview $in/dem.asc --dirs 16 $R --quiet --window 0,0,32,48 -o a.pfm|skyview $in/dem.asc --dirs 8 $R --quiet --window 0,0,32,48 -o a.pfm
piece-tif|a.tif|a.tif.tile|skyview $in/dem.asc --dirs 16 $R --quiet --window 0,0,32,48 -o a.tif|skyview $in/dem.asc --dirs 8 $R --quiet --window 0,0,32,48 -o a.tif"

# state DIR: its files and their checksums, one a line
state() { (cd "$1" && for f in $(ls -A | LC_ALL=C sort); do printf '%s %s\n' "$f" "$(cksum < "$f")"; done); }
# prepare CASE-DIR OLD OUT OTHERS OLDARGS: an empty folder, or one holding the older outputs
prepare() { rm -rf "$1"; mkdir -p "$1"
  [ "$2" = old ] || return 0
  if [ -n "$5" ]; then (cd "$1" && "$hfvis" $5 > /dev/null 2>&1) || bad "setup: older run $5"
  else for f in $3 $4; do printf 'older %s\n' "$f" > "$1/$f"; done; fi
  # the split case writes OUT's stem files, not OUT
  [ "$3" = h.pfm ] && rm -f "$1/h.pfm"; return 0; }

# judge LABEL CASE-DIR RC ERRFILE OUT OTHERS BEFORE-STATE GOOD-DIR
judge() { label=$1; d=$2; rc=$3; err=$4; out=$5; others=$6; before=$7; good=$8
  runs=$((runs + 1))
  temps=$(ls -A "$d" | grep '\.tmp[0-9a-f]\{8\}$')
  if [ "$rc" -eq 0 ]; then
    for f in $out $others; do
      [ "$out" = h.pfm ] && [ "$f" = h.pfm ] && continue
      cmp -s "$d/$f" "$good/$f" || { bad "$label: exit 0 but $f $([ -e "$d/$f" ] && echo differs from the good run || echo is missing)"; return; }
    done
    [ -z "$temps" ] || { bad "$label: exit 0 left $temps"; return; }
    return 0
  fi
  lines=$(wc -l < "$err" | tr -d ' ')
  if [ "$rc" -ge 126 ]; then bad "$label: exit $rc (killed by a signal?), stderr: $(head -n 2 "$err")"; return; fi
  if [ "$lines" != 1 ] || ! grep -q '^hfvis' "$err"; then bad "$label: exit $rc with $lines stderr lines: $(head -n 3 "$err" | tr '\n' '|')"; return; fi
  [ -z "$temps" ] || { bad "$label: temporary file left: $temps ($(cat "$err"))"; return; }
  now=$(state "$d")
  b=$(printf '%s\n' "$before" | grep "^$out ") ; n=$(printf '%s\n' "$now" | grep "^$out ")
  [ "$b" = "$n" ] || { bad "$label: exit $rc ($(cat "$err")) but OUT $out changed (before: ${b:-absent}, now: ${n:-absent})"; return; }
  for f in $others; do
    b=$(printf '%s\n' "$before" | grep "^$f "); n=$(printf '%s\n' "$now" | grep "^$f ")
    [ "$b" = "$n" ] || cmp -s "$d/$f" "$good/$f" || { bad "$label: exit $rc ($(cat "$err")) but $f is neither as it was nor the good run's"; return; }
  done
  return 0
}

# mosaic_check LABEL CASE-DIR EXT: the faulty piece beside the other piece of the older run
mosaic_check() { "$hfvis" mosaic "$2/a.$3" "$in/b.$3" --quiet -o "$dir/mc.$3" > /dev/null 2>&1 || return 0
  cmp -s "$dir/mc.$3" "$in/mosaic8.$3" || bad "$1: the mosaic of what the fault left exits 0 with another raster than the older run's"
  rm -f "$dir/mc.$3"; }

# ---- the good runs ------------------------------------------------------------------------------
have_strace=0
if command -v strace > /dev/null 2>&1 && strace -f -o /dev/null -e trace=write true > /dev/null 2>&1; then have_strace=1
else echo "SKIP: strace not installed or ptrace not permitted: the injected system-call failures are not run"; fi
IFS_NL='
'
good_ok=1
oldifs=$IFS; IFS=$IFS_NL
for c in $cases; do IFS=$oldifs
  name=${c%%|*}; rest=${c#*|}; out=${rest%%|*}; rest=${rest#*|}; others=${rest%%|*}; rest=${rest#*|}
  args=${rest%%|*}
  g=$dir/good/$name; prepare "$g" new
  if (cd "$g" && "$hfvis" $args > /dev/null 2> "$dir/err"); then :; else bad "$name: the good run failed: $(head -n 2 "$dir/err")"; good_ok=0; fi
  if [ "$have_strace" = 1 ]; then
    prepare "$dir/t" new
    (cd "$dir/t" && strace -f -o "$dir/good/$name.trace" -e trace=openat,open,creat,write,pwrite64,close,rename,renameat,renameat2,fsync,fdatasync "$hfvis" $args > /dev/null 2>&1)
  fi
  IFS=$IFS_NL
done
IFS=$oldifs
[ "$good_ok" = 1 ] || { echo "fault: $passed passed, $failed failed"; exit 1; }

# picks TRACE: "syscall N" lines: for each write-path call, its numbers (per thread, as strace's
# when= counts) among the calls of the thread that created the first file, from that creation
# on: the first, second, middle and last
picks() { awk '
  { tid = $1; call = $2; sub(/\(.*/, "", call); cnt[tid, call]++
    if (!start && (call == "openat" || call == "open" || call == "creat") && ($0 ~ /O_CREAT/ || call == "creat") && $0 !~ /= -1/) { start = 1; t = tid }
    if (start && tid == t && (call == "openat" || call == "write" || call == "pwrite64" || call == "close" || call == "rename" || call == "renameat" || call == "renameat2" || call == "fsync" || call == "fdatasync")) {
      k = ++m[call]; num[call, k] = cnt[tid, call] } }
  END { for (c in m) { n = m[c]; print c, num[c, 1]; if (n > 1) print c, num[c, 2]
          if (n > 2) print c, num[c, int((n + 1) / 2)]; if (n > 3) print c, num[c, n] } }' "$1" | sort -u; }

# ---- the faults ---------------------------------------------------------------------------------
oldifs=$IFS; IFS=$IFS_NL
for c in $cases; do IFS=$oldifs
  name=${c%%|*}; rest=${c#*|}; out=${rest%%|*}; rest=${rest#*|}; others=${rest%%|*}; rest=${rest#*|}
  args=${rest%%|*}; oldargs=${rest#*|}
  ext=${out##*.}; piece=0; case $name in piece-*) piece=1 ;; esac
  g=$dir/good/$name; d=$dir/run; before_n=$failed; n0=$runs
  for st in absent old; do
    # a file-size limit of 0 and of 8 blocks, SIGXFSZ at its default action and ignored; stderr
    # goes through a pipe (not limited)
    for lim in 0 8; do for xfsz in default ignored; do
      prepare "$d" "$st" "$out" "$others" "$oldargs"; before=$(state "$d")
      trapcmd=; [ "$xfsz" = ignored ] && trapcmd="trap '' XFSZ;"
      (cd "$d" && { sh -c "$trapcmd ulimit -f $lim; exec \"\$0\" \"\$@\"" "$hfvis" $args 2>&1 > /dev/null
                    echo $? > "$dir/rc"; } | cat > "$dir/err")
      judge "$name ($st OUT, ulimit -f $lim, SIGXFSZ $xfsz)" "$d" "$(cat "$dir/rc")" "$dir/err" "$out" "$others" "$before" "$g"
      [ "$piece" = 1 ] && mosaic_check "$name ($st, ulimit -f $lim)" "$d" "$ext"
    done; done
    [ "$have_strace" = 1 ] || continue
    for p in $(picks "$g.trace" | tr ' ' ':'); do call=${p%%:*}; k=${p#*:}
      for e in ENOSPC EIO; do
        [ "$e" = EIO ] && [ "$call" != close ] && [ "$call" != fsync ] && [ "$call" != write ] && [ "$call" != pwrite64 ] && continue
        [ "$st" = absent ] && [ "$e" = EIO ] && continue
        prepare "$d" "$st" "$out" "$others" "$oldargs"; before=$(state "$d")
        (cd "$d" && strace -f -o /dev/null -e trace="$call" -e inject="$call":error="$e":when="$k" "$hfvis" $args > /dev/null 2> "$dir/err")
        rc=$?
        judge "$name ($st OUT, $call #$k fails with $e)" "$d" "$rc" "$dir/err" "$out" "$others" "$before" "$g"
        [ "$piece" = 1 ] && mosaic_check "$name ($st OUT, $call #$k $e)" "$d" "$ext"
      done
    done
  done
  [ "$failed" -eq "$before_n" ] && ok "$name: $((runs - n0)) faulty runs: each exit 0 with the good output, or one error line, OUT as it was, no temporary file"
  IFS=$IFS_NL
done
IFS=$oldifs
# ---- an interrupt while a raster's set of files is published ----------------------------------
# A raster alone (.pfm, .pgm) or with its sidecars (.asc + .prj, .bil + .hdr + .prj) replacing an
# older set: strace
# holds one call of the write path for a second (the creation of each temporary file, each
# rename: the older files moved aside, the new ones moved in) and SIGINT or SIGTERM (in turn)
# is sent meanwhile. Afterwards no temporary file may remain and the set must be the older one
# or the new one, whole, never a mix; an exit 0 must have written the new one.
if [ "$have_strace" = 1 ]; then
  for set in "pfm|o.pfm" "pgm|o.pgm" "asc|o.asc o.prj" "bil|o.bil o.hdr o.prj"; do
    ext=${set%%|*}; files=${set#*|}; before_n=$failed; n0=$runs
    args="skyview $in/dem.asc --dirs 8 --quiet -o o.$ext"; oldargs="skyview $in/dem.asc --dirs 4 --quiet -o o.$ext"
    g=$dir/sig_good; prepare "$g" new; (cd "$g" && "$hfvis" $args > /dev/null 2>&1) || bad "sig $ext: the good run failed"
    prepare "$dir/t" old o.$ext "" "$oldargs"
    (cd "$dir/t" && strace -f -o "$dir/sig.trace" -e trace=openat,rename,renameat,renameat2 "$hfvis" $args > /dev/null 2>&1)
    # the held calls: "CALL N", N counted among the traced calls of that name
    points=$(awk '{ call = $2; sub(/\(.*/, "", call); cnt[call]++
        if (call ~ /^rename/ || (call == "openat" && $0 ~ /O_CREAT/)) print call, cnt[call] }' "$dir/sig.trace")
    oldifs=$IFS; IFS=$IFS_NL; i=0
    for pt in $points; do IFS=$oldifs
      call=${pt% *}; k=${pt#* }; i=$((i + 1)); sig=INT; [ $((i % 2)) -eq 0 ] && sig=TERM
      d=$dir/run; prepare "$d" old o.$ext "" "$oldargs"; before=$(state "$d"); rm -f "$dir/sig.trace" "$dir/sig.sent"
      # the poller: once the trace shows call number k begun (strace prints it before holding
      # it), signal the tool. The tool runs in the foreground: a background job has SIGINT ignored.
      ( j=0; while [ $j -lt 400 ]; do
          if [ -f "$dir/sig.trace" ] && [ "$(grep -c " $call(" "$dir/sig.trace")" -ge "$k" ]; then
            # the pid on the held call's line (strace -f: a worker thread's exit may come first)
            kill -"$sig" "$(awk -v c=" $call(" 'index($0, c) { print $1; exit }' "$dir/sig.trace")" 2> /dev/null &&
              : > "$dir/sig.sent"; exit 0
          fi
          sleep 0.05; j=$((j + 1)); done ) &
      poller=$!
      # (an inner shell waits for strace, so that its "Terminated" line goes to /dev/null)
      sh -c 'cd "$1" && shift && "$@"; exit $?' sh "$d" strace -f -o "$dir/sig.trace" -e trace="$call" \
        -e inject="$call":delay_enter=1000000:when="$k" "$hfvis" $args > /dev/null 2>&1
      rc=$?; wait "$poller"; runs=$((runs + 1))
      label="sig $ext: SIG$sig while $call #$k is held (exit $rc)"
      temps=$(ls -A "$d" | grep '\.tmp[0-9a-f]\{8\}$')
      now=$(state "$d"); new=1; for f in $files; do cmp -s "$d/$f" "$g/$f" || new=0; done
      if [ ! -f "$dir/sig.sent" ]; then bad "$label: the tool was not signalled while held"
      elif [ -n "$temps" ]; then bad "$label: temporary files left: $(echo $temps)"
      elif [ "$rc" -eq 0 ] && [ "$new" = 0 ]; then bad "$label: exit 0 without the new set"
      elif [ "$now" != "$before" ] && [ "$new" = 0 ]; then bad "$label: neither the older set nor the new one: $(ls -A "$d" | tr '\n' ' ')"
      fi
      IFS=$IFS_NL
    done
    IFS=$oldifs
    [ "$runs" -gt "$n0" ] || bad "sig $ext: no write-path call found in the trace"
    [ "$failed" -eq "$before_n" ] && ok "sig $ext: SIGINT/SIGTERM during each of $((runs - n0)) held calls of publishing o.$ext and its sidecars: no temporary file, the older set or the new one whole"
  done
fi
echo "fault: $passed passed, $failed failed ($runs faulty runs)"
[ "$failed" -eq 0 ]
