#!/bin/sh
# valgrind.sh - the whole suite under valgrind memcheck: every test program in BUILD/test, every
# example (writing into a scratch folder) and test/cli_test.sh with the CLI wrapped in valgrind.
# Memory errors and definite or indirect leaks fail a program (libdeflate's run_tests.sh runs
# its tests the same way). Prints one line per program, then
# "valgrind: N programs, E errors, L bytes leaked, M failed, S s".
# usage: sh test/valgrind.sh BUILD [NAME...]   (`make valgrind` builds BUILD = build/test first)
#   NAMEs (test_x, an example such as 06_lava, or cli) run only those programs; default all.
build=$1; [ $# -gt 0 ] && shift; only=" $* "
[ -n "$build" ] && [ -d "$build/test" ] || { echo "usage: sh test/valgrind.sh BUILD [NAME...]"; exit 2; }
command -v valgrind > /dev/null 2>&1 || { echo "valgrind: not installed"; exit 2; }
vg="valgrind --error-exitcode=1 --leak-check=full --errors-for-leak-kinds=definite,indirect"
scratch=$(mktemp -d 2>/dev/null || echo "$build/vgscratch"); mkdir -p "$scratch/out" || exit 1
case $build in /*) abs=$build ;; *) abs=$(pwd)/$build ;; esac
programs=0; failed=0; errors=0; leaked=0; t0=$(date +%s)

# tally NAME RC SECONDS: read the logs $scratch/vg.*.log of the last program, add them up.
tally() {
  set -- "$1" "$2" "$3" $(cat "$scratch"/vg.*.log 2>/dev/null | awk '
    /ERROR SUMMARY:/ { e += $4 }
    /definitely lost:|indirectly lost:/ { v = $4; gsub(",", "", v); l += v }
    END { print e + 0, l + 0 }')
  programs=$((programs + 1)); errors=$((errors + $4)); leaked=$((leaked + $5))
  if [ "$2" -ne 0 ] || [ "$4" -ne 0 ] || [ "$5" -ne 0 ]; then
    failed=$((failed + 1)); cat "$scratch/log"; cat "$scratch"/vg.*.log
    echo "FAIL $1: exit $2, $4 errors, $5 bytes leaked (${3}s)"
  else echo "ok   $1: 0 errors, 0 bytes leaked (${3}s)"; fi
  rm -f "$scratch"/vg.*.log
}

# wanted NAME: true if no NAMEs were given or NAME is one of them.
wanted() { [ "$only" = "  " ] || case $only in *" $1 "*) true ;; *) false ;; esac; }

for t in "$build"/test/test_*; do
  [ -x "$t" ] && wanted "$(basename "$t")" || continue
  s=$(date +%s)
  $vg --log-file="$scratch/vg.%p.log" "$t" > "$scratch/log" 2>&1; rc=$?
  tally "$(basename "$t")" "$rc" $(($(date +%s) - s))
done
for e in "$build"/examples/*; do
  [ -x "$e" ] && wanted "$(basename "$e")" || continue
  s=$(date +%s)
  $vg --log-file="$scratch/vg.%p.log" "$e" "$scratch/out" > "$scratch/log" 2>&1; rc=$?
  tally "example $(basename "$e")" "$rc" $(($(date +%s) - s))
done
if [ -x "$build/hfvis" ] && wanted cli; then
  # The wrapper keeps valgrind's report out of the CLI's stderr, which cli_test.sh inspects.
  printf '#!/bin/sh\nexec %s --log-file="%s/vg.%%p.log" "%s/hfvis" "$@"\n' "$vg" "$scratch" "$abs" > "$scratch/hfvis"
  chmod +x "$scratch/hfvis"
  s=$(date +%s)
  sh test/cli_test.sh "$scratch/hfvis" "$scratch/out" > "$scratch/log" 2>&1; rc=$?
  tally "cli_test.sh ($(ls "$scratch"/vg.*.log 2>/dev/null | wc -l | tr -d ' ') runs)" "$rc" $(($(date +%s) - s))
fi
rm -rf "$scratch"
echo "valgrind: $programs programs, $errors errors, $leaked bytes leaked, $failed failed, $(($(date +%s) - t0)) s"
[ "$failed" -eq 0 ]
