#!/bin/sh
# portability.sh - the portability matrix (`make portability`): the whole `make test` (library,
# examples, tests, CLI, install and vendoring checks; -Werror) with gcc and clang at -O0 and -O2
# and with tcc, the library with -DHFVIS_NO_STDIO -Werror per compiler (and no stdio symbol
# referenced), and hfvis.h as C++98/11/17 with g++ and clang++. A compiler that is absent is
# skipped with a message (only cc and make are required). Prints one table row per cell and exits
# non-zero if any cell failed. CPU heavy (five full test runs): run it with nice.
# usage: sh test/portability.sh   (from the repository root; PORT_JOBS = make -j, default 2;
# PORT_ONLY = space-separated row names to run, e.g. "tcc nostdio-gcc", default all)
jobs=${PORT_JOBS:-2}
only=${PORT_ONLY:-}
out=build/port
[ -f hfvis.h ] && [ -f Makefile ] || { echo "portability: run from the repository root"; exit 2; }
mkdir -p "$out" || exit 1
table=$out/table.txt
: > "$table"
nfail=0
warn=$(make -pn -q lib 2>/dev/null | sed -n 's/^WARN := //p')
[ -n "$warn" ] || warn="-std=c99 -pedantic -Wall -Wextra"

have() { command -v "$1" > /dev/null 2>&1; }
want() { [ -z "$only" ] && return 0; case " $only " in *" $1 "*) return 0;; esac; return 1; }
version() { v=$("$1" -dumpfullversion 2>/dev/null); [ -n "$v" ] || v=$("$1" -dumpversion 2>/dev/null); echo "${v:-?}"; }
# row NAME COMPILER VERSION FLAGS RESULT DETAIL
row() {
  printf '%-13s %-8s %-7s %-40s %-5s %s\n' "$1" "$2" "$3" "$4" "$5" "$6" | tee -a "$table"
  [ "$5" = ok ] || [ "$5" = skip ] || nfail=$((nfail + 1))
}

# The full suite: make test (config=test, werror=1) with CC and an optional opt=, into its own
# build folder so that compilers and levels never share objects.
suite() { # NAME CC FLAGS-LABEL [make args...]
  name=$1; cc=$2; label=$3; shift 3
  want "$name" || return 0
  if ! have "$cc"; then row "$name" "$cc" - "$label" skip "$cc not installed"; return 0; fi
  log=$out/$name.log
  start=$(date +%s)
  if make --no-print-directory -j"$jobs" test CC="$cc" BUILD="$out/$name" "$@" > "$log" 2>&1; then res=ok; else res=FAIL; fi
  secs=$(($(date +%s) - start))
  counts=$(grep '^tests: ' "$log" | tail -n 1 | sed 's/^tests: //')
  nwarn=$(grep -c 'warning:' "$log")
  row "$name" "$cc" "$(version "$cc")" "$label" "$res" "${counts:-no result line, see $log}; $nwarn warnings; ${secs} s"
}

# The library alone with -DHFVIS_NO_STDIO: no file wrappers, so no stdio function referenced.
nostdio() { # CC
  cc=$1; name=nostdio-$cc
  want "$name" || return 0
  if ! have "$cc"; then row "$name" "$cc" - "-DHFVIS_NO_STDIO" skip "$cc not installed"; return 0; fi
  d=$out/$name; rm -rf "$d"; mkdir -p "$d"; log=$out/$name.log; : > "$log"
  res=ok
  for f in hfvis ssao voxel; do
    # shellcheck disable=SC2086 # $warn is a list of flags
    $cc $warn -O2 -Werror -DHFVIS_NO_STDIO -c $f.c -o "$d/$f.o" >> "$log" 2>&1 || res=FAIL
  done
  detail="3 files compile"
  if [ "$res" = ok ]; then
    stdio=$(nm -u "$d"/*.o 2>/dev/null | awk '{print $NF}' | grep -E '^_?(fopen|fclose|fread|fwrite|fseek|ftell|fflush|remove|rename|f?printf|puts|fputs)$' | sort -u | tr '\n' ' ')
    if [ -n "$stdio" ]; then res=FAIL; detail="references $stdio"; fi
  else detail="compile failed, see $log"; fi
  row "$name" "$cc" "$(version "$cc")" "-std=c99 -O2 -Werror -DHFVIS_NO_STDIO" "$res" "$detail; no stdio symbol"
}

# hfvis.h as C++ (test/cxx_header.cpp), syntax only, every standard the compiler knows of these.
cxx() { # CXX
  cxx=$1; name=cxx-$cxx
  want "$name" || return 0
  if ! have "$cxx"; then row "$name" "$cxx" - "-fsyntax-only" skip "$cxx not installed"; return 0; fi
  res=ok; passed=""; log=$out/$name.log; : > "$log"
  for std in c++98 c++11 c++17; do
    if $cxx -std=$std -Wall -Wextra -Werror -pedantic -fsyntax-only -I. test/cxx_header.cpp >> "$log" 2>&1
    then passed="$passed $std"; else res=FAIL; passed="$passed $std:FAIL"; fi
  done
  row "$name" "$cxx" "$(version "$cxx")" "-Wall -Wextra -pedantic -Werror" "$res" "hfvis.h as${passed}"
}

printf '%-13s %-8s %-7s %-40s %-5s %s\n' row compiler version flags result "tests / detail" | tee "$table"
suite gcc-O2   gcc   "-std=c99 -O2 -Werror (config=test)"
suite gcc-O0   gcc   "-std=c99 -O0 -Werror (opt=0)"          opt=0
suite clang-O2 clang "-std=c99 -O2 -Werror (config=test)"
suite clang-O0 clang "-std=c99 -O0 -Werror (opt=0)"          opt=0
suite tcc      tcc   "-std=c99 -Werror (tcc: no optimizer)"
for c in gcc clang tcc; do nostdio "$c"; done
for c in g++ clang++; do cxx "$c"; done
echo "portability: $nfail failed cells; table in $table, logs in $out/"
[ "$nfail" -eq 0 ]
