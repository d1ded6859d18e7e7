#!/bin/sh
# scale_test.sh - the README's scale-out recipes ("Rasters larger than memory: tiles") run on the
# real engines: GNU parallel, xargs -P and a Slurm job array with its afterok mosaic.
#
# The recipes are read out of README.md and run as written, with three substitutions that fit them
# to a small raster: the input dtm.tif is dtm.asc (written here with awk: integer heights, exact as
# floats), and the budgets 4G / 8G are 4M / 8M, so that the 400 x 300 raster (cell 25 m, R = 1000
# m, halo 45 cells) is cut into 12 windows (parallel) and 4 windows (Slurm). Every mosaic must
# equal the whole run byte for byte.
#
# Slurm: a private single-node cluster (munged, slurmctld, slurmd; configuration, state, sockets and
# logs in a temporary folder, its own ports) is started here and stopped on any exit. One array
# task is made to fail (its piece's name is taken by a folder, so the write fails); the test checks
# that only that task failed, that it left no piece, that afterok holds the mosaic back, that a
# mosaic of what is there refuses the missing piece, and that rerunning the failed index as the
# README says, then the mosaic, gives the whole run's bytes.
# SKIP (exit 0, one "SKIP: reason" line) where GNU parallel or Slurm/munge are not installed or
# the cluster does not start.
# usage: sh test/scale_test.sh BUILD/hfvis            (make scale-test)
hfvis=$1
[ -n "$hfvis" ] && [ -x "$hfvis" ] || { echo "usage: sh test/scale_test.sh BUILD/hfvis"; exit 2; }
repo=$(cd "$(dirname "$0")/.." && pwd)
hfvis=$(cd "$(dirname "$hfvis")" && pwd)/$(basename "$hfvis")
dir=$(mktemp -d "${TMPDIR:-/tmp}/hfvis_scale.XXXXXX") || exit 1
passed=0; failed=0
ok()  { passed=$((passed + 1)); echo "ok   scale $1"; }
bad() { failed=$((failed + 1)); echo "FAIL scale $1"; }
TIMEOUT=180                      # seconds any wait for the cluster may take before it fails

# ---- the daemons this test starts, stopped on every exit ---------------------------------------
daemons=""                       # pid files of the daemons started, newest first
stop_all() {
  if [ -n "${SLURM_CONF:-}" ] && [ -n "$daemons" ]; then
    scancel --quiet --partition=main > /dev/null 2>&1
    i=0; while [ "$i" -lt 20 ] && [ -n "$(squeue -h -o %i 2> /dev/null)" ]; do sleep 0.5; i=$((i + 1)); done
  fi
  for pf in $daemons; do
    pid=$(cat "$pf" 2> /dev/null) || continue
    [ -n "$pid" ] && kill "$pid" 2> /dev/null || continue
    i=0; while kill -0 "$pid" 2> /dev/null && [ "$i" -lt 40 ]; do sleep 0.25; i=$((i + 1)); done
    kill -9 "$pid" 2> /dev/null
  done
  daemons=""
}
finish() { rc=$?; trap - EXIT INT TERM HUP; stop_all; rm -rf "$dir"; exit "$rc"; }
trap finish EXIT
trap 'exit 130' INT TERM HUP

# ---- the raster, the tool on the PATH, the README's recipes --------------------------------------
mkdir -p "$dir/bin" || exit 1
ln -s "$hfvis" "$dir/bin/hfvis"
PATH=$dir/bin:$PATH; export PATH
LC_ALL=C awk 'BEGIN { w = 400; h = 300; srand(11)
  printf "ncols %d\nnrows %d\nxllcorner 400000\nyllcorner 4400000\ncellsize 25\nNODATA_value -9999\n", w, h
  for (y = 0; y < h; y++) { s = ""
    for (x = 0; x < w; x++) {
      v = 1500 + int(600 * sin(x / 41) * cos(y / 33) + 200 * sin((x + 2 * y) / 9) + 40 * rand())
      if (x == 200) v += 300                                   # a one-cell wall across window edges
      if (x >= 150 && x < 160 && y >= 100 && y < 104) v = -9999 # a hole
      s = s " " v }
    print s } }' > "$dir/dtm.asc"
"$hfvis" skyview "$dir/dtm.asc" --dirs 32 --max-distance 1000 --quiet -o "$dir/whole.tif" \
  || { bad "the whole run failed"; exit 1; }

# recipe MARK: the first ``` block after the README line starting with MARK, fitted to this raster
recipe() {
  awk -v m="$1" 'index($0, m) == 1 { f = 1; next } f && /^```/ { if (b) exit; b = 1; next } f && b' \
    "$repo/README.md" | sed -e 's/dtm\.tif/dtm.asc/g' -e 's/ \([48]\)G\([ ]\)/ \1M\2/g' -e 's/ \([48]\)G$/ \1M/'
}
# commands FILE: the recipe's commands one a line (continuation lines joined, comments dropped)
commands() { awk '/^#/ || /^ *#/ { next } { if (sub(/\\$/, "")) { c = c $0; next } print c $0; c = "" }' "$1"; }
# fresh NAME: an empty work folder NAME holding the raster and the repository's examples/
fresh() { rm -rf "${dir:?}/$1"; mkdir -p "$dir/$1" && cp "$dir/dtm.asc" "$dir/$1/" && ln -s "$repo/examples" "$dir/$1/examples"; }
windows() { n=$(wc -l < "$1" | tr -d ' '); echo "$n windows"; }

recipe '**One machine, GNU parallel' > "$dir/par.txt"
[ -s "$dir/par.txt" ] || { bad "README: the GNU parallel recipe not found"; exit 1; }
commands "$dir/par.txt" > "$dir/par.cmds"

# ---- xargs -P (always there) and GNU parallel -----------------------------------------------------
for engine in xargs parallel; do
  other=parallel; [ "$engine" = parallel ] && other=xargs
  if [ "$engine" = parallel ] && ! parallel --version 2> /dev/null | grep -q 'GNU parallel'; then
    echo "SKIP: GNU parallel not installed (Debian: parallel)"; continue; fi
  fresh "$engine"
  grep -v "^$other " "$dir/par.cmds" > "$dir/$engine.sh"
  if (cd "$dir/$engine" && HOME=$dir/$engine PARALLEL_HOME=$dir/$engine/.parallel . "$dir/$engine.sh") \
       > "$dir/$engine.log" 2>&1; then
    if cmp -s "$dir/$engine/svf.tif" "$dir/whole.tif"; then
      ok "$engine: README recipe, $(windows "$dir/$engine/tiles.txt"), mosaic = whole run byte for byte"
    else bad "$engine: the mosaic differs from the whole run"; fi
  else bad "$engine: the recipe failed: $(tail -n 3 "$dir/$engine.log")"; fi
done

# ---- Slurm -------------------------------------------------------------------------------------
skip_slurm() { echo "SKIP: Slurm: $1"; }
slurm() {
  for p in munged munge slurmctld slurmd sbatch squeue scontrol scancel sinfo; do
    command -v "$p" > /dev/null 2>&1 || { skip_slurm "$p not installed (Debian: slurm-wlm, munge)"; return 0; }
  done
  s=$dir/slurm; mkdir -p "$s/munge" "$s/state" "$s/spool" "$s/log" || return 1
  chmod 700 "$s" "$s/munge"
  dd if=/dev/urandom of="$s/munge.key" bs=1024 count=1 2> /dev/null && chmod 600 "$s/munge.key"
  munged --force --socket="$s/munge/sock" --key-file="$s/munge.key" --log-file="$s/log/munged.log" \
         --pid-file="$s/munge/pid" --seed-file="$s/munge/seed" > /dev/null 2>&1 \
    || { skip_slurm "munged does not start: $(tail -n 1 "$s/log/munged.log" 2> /dev/null)"; return 0; }
  daemons="$s/munge/pid"
  host=$(hostname -s); port=$((20000 + $$ % 20000))
  # Memory is not a consumable (CR_Core) and the node's configuration is taken as given
  # (config_overrides), so the README's --mem=9G and --mem=64G are accepted on a small machine.
  cat > "$s/slurm.conf" << EOF
ClusterName=hfvisscale
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=$(id -un)
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$s/munge/sock
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SlurmdParameters=config_overrides
StateSaveLocation=$s/state
SlurmdSpoolDir=$s/spool
SlurmctldPidFile=$s/slurmctld.pid
SlurmdPidFile=$s/slurmd.pid
SlurmctldLogFile=$s/log/slurmctld.log
SlurmdLogFile=$s/log/slurmd.log
ReturnToService=2
MpiDefault=none
JobAcctGatherType=jobacct_gather/none
MinJobAge=600
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc 2> /dev/null || echo 2) RealMemory=100000 State=UNKNOWN
PartitionName=main Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
  echo "CgroupPlugin=cgroup/v1" > "$s/cgroup.conf"
  SLURM_CONF=$s/slurm.conf; export SLURM_CONF
  slurmctld -f "$SLURM_CONF" > "$s/log/slurmctld.out" 2>&1 && daemons="$s/slurmctld.pid $daemons" \
    || { skip_slurm "slurmctld does not start: $(tail -n 1 "$s/log/slurmctld.out")"; return 0; }
  slurmd -f "$SLURM_CONF" > "$s/log/slurmd.out" 2>&1 && daemons="$s/slurmd.pid $daemons" \
    || { skip_slurm "slurmd does not start: $(tail -n 1 "$s/log/slurmd.out")"; return 0; }
  i=0; until [ "$(sinfo -h -o %T 2> /dev/null)" = idle ]; do
    i=$((i + 1)); [ "$i" -gt 60 ] && { skip_slurm "the node is not idle after 30 s: $(tail -n 1 "$s/log/slurmd.log" 2> /dev/null)"; return 0; }
    sleep 0.5; done
  ok "slurm: a single-node cluster (slurmctld + slurmd + munged) is up"

  recipe '**A Slurm job array' > "$dir/slurm.txt"
  grep -q '^JOBID=' "$dir/slurm.txt" || { bad "README: the Slurm recipe not found"; return 1; }
  # the recipe in three parts: up to the array's sbatch, the array's sbatch, the mosaic's sbatch
  awk '/^JOBID=/ { exit } { print }' "$dir/slurm.txt" > "$dir/slurm_a.sh"
  grep '^JOBID=' "$dir/slurm.txt" > "$dir/slurm_b.sh"
  awk 'f { print } /^JOBID=/ { f = 1 }' "$dir/slurm.txt" > "$dir/slurm_c.sh"
  fresh work; cd "$dir/work" || return 1
  . "$dir/slurm_a.sh" > "$dir/slurm_a.log" 2>&1 || { bad "slurm: the recipe's preparation failed: $(tail -n 2 "$dir/slurm_a.log")"; return 1; }
  [ "$N" -ge 3 ] || { bad "slurm: $N windows, the test wants at least 3"; return 1; }
  k=1; win=$(sed -n "$((k + 1))p" tiles.txt); piece=pieces/svf_$(echo "$win" | tr , _).tif
  mkdir "$piece"                         # task k's output name is taken: its write fails
  . "$dir/slurm_b.sh" && . "$dir/slurm_c.sh" > "$dir/mosaic_id" || { bad "slurm: sbatch failed"; return 1; }
  array=${JOBID%%;*}; mosaic=$(awk '{ print $NF }' "$dir/mosaic_id")
  # the array ends; the mosaic stays pending, held by afterok
  i=0; while [ -n "$(squeue -h -j "$array" -o %i 2> /dev/null)" ]; do
    i=$((i + 1)); [ "$i" -gt $((TIMEOUT * 2)) ] && { bad "slurm: the array did not finish in $TIMEOUT s"; return 1; }
    sleep 0.5; done
  states=$(scontrol -o show job "$array" | sed -n 's/.*ArrayTaskId=\([0-9]*\) .*JobState=\([A-Z]*\) .*/\1 \2/p' | sort -n)
  expect=$(i=0; while [ "$i" -lt "$N" ]; do [ "$i" -eq "$k" ] && echo "$i FAILED" || echo "$i COMPLETED"; i=$((i + 1)); done)
  if [ "$states" = "$expect" ]; then ok "slurm: array of $N windows, task $k FAILED (its piece's name taken), the others COMPLETED"
  else bad "slurm: task states: $(echo "$states" | tr '\n' ' ') (expected task $k alone FAILED)"; fi
  log=logs/tile_${array}_$k.log
  if [ -f "$log" ] && [ "$(grep -c '^hfvis' "$log")" -ge 1 ] && grep '^hfvis' "$log" | grep -qv 'progress\|done'; then
    ok "slurm: the failed task's log names the error: $(grep '^hfvis' "$log" | tail -n 1)"
  else bad "slurm: the failed task's log has no error line: $(tail -n 2 "$log" 2> /dev/null)"; fi
  rmdir "$piece"
  if [ -n "$(ls pieces | grep -Ev '^svf_[0-9_]*\.tif(\.tile)?$')" ] || [ -e "$piece.tile" ] \
     || [ "$(ls pieces | grep -c '\.tif$')" -ne $((N - 1)) ]; then
    bad "slurm: the failed task left a piece, a sidecar or a temporary file: $(ls pieces | tr '\n' ' ')"
  else ok "slurm: the failed task left no piece, sidecar or temporary file ($((N - 1)) pieces)"; fi
  i=0; reason=; while [ "$i" -lt 60 ]; do
    reason=$(squeue -h -j "$mosaic" -o '%T %r' 2> /dev/null); [ "$reason" = "PENDING DependencyNeverSatisfied" ] && break
    sleep 0.5; i=$((i + 1)); done
  if [ "$reason" = "PENDING DependencyNeverSatisfied" ] && [ ! -e svf.tif ]; then
    ok "slurm: afterok holds the mosaic back (job $mosaic: $reason), no svf.tif"
  else bad "slurm: the mosaic job is '$reason', svf.tif $([ -e svf.tif ] && echo written || echo absent)"; fi
  if hfvis mosaic pieces/svf_*.tif -o svf.tif > /dev/null 2> "$dir/err"; then bad "slurm: a mosaic without piece $k exited 0"
  elif [ "$(wc -l < "$dir/err" | tr -d ' ')" = 1 ] && grep -q 'missing' "$dir/err" && [ ! -e svf.tif ]; then
    ok "slurm: the mosaic run by hand refuses the missing piece: $(cat "$dir/err")"
  else bad "slurm: the mosaic without piece $k: $(head -n 2 "$dir/err")"; fi
  # the README's rerun: the failed index, then the mosaic (the held one cancelled)
  scancel "$mosaic"
  rerun=$(sed -n 's/.*(`\(JOBID=$(sbatch [^`]*\)`).*/\1/p' "$repo/README.md" | head -n 1)
  [ -n "$rerun" ] || { bad "README: the rerun command not found"; return 1; }
  eval "$(echo "$rerun" | sed "s/--array=[0-9,]*/--array=$k/")" || { bad "slurm: the rerun's sbatch failed"; return 1; }
  . "$dir/slurm_c.sh" > "$dir/mosaic_id" || { bad "slurm: the mosaic's sbatch failed"; return 1; }
  mosaic=$(awk '{ print $NF }' "$dir/mosaic_id")
  i=0; while [ -n "$(squeue -h -j "${JOBID%%;*},$mosaic" -o %i 2> /dev/null)" ]; do
    i=$((i + 1)); [ "$i" -gt $((TIMEOUT * 2)) ] && { bad "slurm: the rerun and mosaic did not finish in $TIMEOUT s"; return 1; }
    sleep 0.5; done
  if cmp -s svf.tif "$dir/whole.tif"; then ok "slurm: index $k rerun, then the mosaic: svf.tif = whole run byte for byte"
  else bad "slurm: after the rerun, svf.tif $([ -e svf.tif ] && echo differs from the whole run || echo is missing): $(cat logs/mosaic_"$mosaic".log 2> /dev/null | head -n 2)"; fi
  cd "$dir" || return 1
}
slurm || bad "slurm: setup failed"
stop_all
echo "scale: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
