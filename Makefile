# hfvis - plain Makefile. Variables: CC, CXX, CFLAGS, config=release|debug|test|sanitize|coverage,
# werror=1, opt=0|1|2|3|s (replaces the config's -O level; outputs go to <build dir>-O<opt>),
# PREFIX and DESTDIR (install, uninstall), FUZZ_SECONDS (fuzz).
CC ?= cc
CXX ?= c++
config ?= release
werror ?= 0
PREFIX ?= /usr/local
FUZZ_SECONDS ?= 30
FUZZ_CC ?= clang

WARN := -std=c99 -pedantic -Wall -Wextra -Wshadow -Wstrict-prototypes -Wmissing-prototypes \
        -Wundef -Wvla -Wcast-qual -Wdouble-promotion -Wfloat-conversion \
        -Wimplicit-fallthrough -Wmissing-field-initializers
BASEFLAGS := $(WARN) -ffp-contract=off

ifeq ($(config),release)
  BUILD := build
  OPT := -O2
else ifeq ($(config),debug)
  BUILD := build/debug
  OPT := -O0 -g -DHFVIS_ENABLE_ASSERTS
else ifeq ($(config),test)
  BUILD := build/test
  OPT := -O2 -g -DHFVIS_ENABLE_ASSERTS
else ifeq ($(config),sanitize)
  BUILD := build/sanitize
  OPT := -O1 -g -DHFVIS_ENABLE_ASSERTS -fsanitize=address,undefined,float-cast-overflow -fno-sanitize-recover=all -fno-omit-frame-pointer
else ifeq ($(config),coverage)
  BUILD := build/coverage
  OPT := -O0 -g --coverage
else
  $(error unknown config '$(config)': use release, debug, test, sanitize or coverage)
endif
ifeq ($(werror),1)
  OPT += -Werror
endif
ifneq ($(opt),)
  OPT := $(filter-out -O%,$(OPT)) -O$(opt)
  BUILD := $(BUILD)-O$(opt)
endif

ALL_CFLAGS := $(BASEFLAGS) $(OPT) $(CFLAGS)
LDLIBS := -lm

LIBSRC := hfvis.c ssao.c voxel.c
LIBOBJ := $(LIBSRC:%.c=$(BUILD)/obj/%.o)
LIB := $(BUILD)/libhfvis.a
EXAMPLES := $(patsubst examples/%.c,$(BUILD)/examples/%,$(wildcard examples/*.c))
CLI := $(BUILD)/hfvis
BENCH := $(BUILD)/bench
TESTS := $(patsubst test/%.c,$(BUILD)/test/%,$(wildcard test/test_*.c))
FUZZERS := $(patsubst test/fuzz/%.c,%,$(wildcard test/fuzz/fuzz_*.c))

.PHONY: all lib examples test check sanitize tsan scale-test fuzz bench demo install symbols cxx update-golden clean run-tests test-programs
all: $(LIB) $(CLI) $(EXAMPLES)
lib: $(LIB)
examples: $(EXAMPLES) $(CLI)

$(BUILD)/obj/%.o: %.c hfvis.h
	@mkdir -p $(dir $@)
	$(CC) $(ALL_CFLAGS) -c $< -o $@
$(LIB): $(LIBOBJ)
	@rm -f $@
	ar rcs $@ $^
$(BUILD)/examples/%: examples/%.c examples/common.h examples/fields.h $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(ALL_CFLAGS) -I. $< $(LIB) $(LDLIBS) -o $@
$(CLI): $(wildcard examples/cli/*.c) examples/cli/cli.h examples/common.h examples/raster_io.h $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(ALL_CFLAGS) $(PTHREAD) -I. examples/cli/main.c $(LIB) $(LDLIBS) -o $@
$(BENCH): examples/bench/bench.c $(wildcard examples/bench/bench_*.c) examples/bench/bench.h examples/common.h examples/fields.h examples/raster_io.h examples/zio.h $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(ALL_CFLAGS) -I. examples/bench/bench.c $(wildcard examples/bench/bench_*.c) $(LIB) $(LDLIBS) -o $@
$(BUILD)/test/%: test/%.c test/test.h test/test_dir.h examples/fields.h $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(ALL_CFLAGS) -I. $< $(LIB) $(LDLIBS) -o $@
# The library's calls run concurrently (hfvis.h, "Threads"): POSIX threads, test only.
PTHREAD ?= -pthread
THREAD_TEST := $(BUILD)/thread/thread_test
$(THREAD_TEST): test/thread_test.c test/test.h $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(ALL_CFLAGS) $(PTHREAD) -I. $< $(LIB) $(LDLIBS) -o $@

# make test: -Werror, every test program, the examples as smoke tests, the C++ header compile
# and the symbol-prefix check; the last line is "tests: N passed, M failed". JOBS (default 2) is
# the build's -j (unless make was given its own -j) and the number of test steps run at once.
JOBS ?= 2
JOBS_FLAG = $(if $(filter -j%,$(MAKEFLAGS)),,-j$(JOBS))
test check:
	@$(MAKE) --no-print-directory $(JOBS_FLAG) config=test werror=1 test-programs
	@$(MAKE) --no-print-directory config=test werror=1 run-tests
sanitize:
	@$(MAKE) --no-print-directory $(JOBS_FLAG) config=sanitize werror=1 test-programs
	@$(MAKE) --no-print-directory config=sanitize werror=1 run-tests
	@$(MAKE) --no-print-directory tsan
# make tsan: test/thread_test.c under ThreadSanitizer (part of make sanitize); SKIP when the
# compiler has no TSan runtime.
tsan:
	@mkdir -p build/tsan
	@if printf 'int main(void){return 0;}\n' | $(CC) -fsanitize=thread $(PTHREAD) -x c - -o build/tsan/probe 2>/dev/null; then \
	  $(CC) $(BASEFLAGS) -Werror -O1 -g -fsanitize=thread $(PTHREAD) -I. test/thread_test.c $(LIBSRC) $(LDLIBS) -o build/tsan/thread_test && \
	  TSAN_OPTIONS=halt_on_error=1 build/tsan/thread_test > build/tsan/log 2>&1 && tail -n 1 build/tsan/log && echo "tsan: no data race" || \
	  { cat build/tsan/log; echo "tsan: FAILED"; exit 1; }; \
	else echo "SKIP tsan: $(CC) has no ThreadSanitizer runtime"; fi
# make scale-test: the README's scale-out recipes on GNU parallel, xargs -P and a private
# single-node Slurm (test/scale_test.sh, ~30 s), then every output format under a file-size limit
# and injected write-path failures (test/fault_cli_test.sh, 1-4 min); each prints "SKIP: reason"
# for what is missing (the engines, strace).
scale-test:
	@$(MAKE) --no-print-directory config=test werror=1 build/test/hfvis
	@sh test/scale_test.sh build/test/hfvis
	@sh test/fault_cli_test.sh build/test/hfvis
test-programs: $(TESTS) $(EXAMPLES) $(CLI) $(BENCH) $(THREAD_TEST)
run-tests: test-programs
	@CC="$(CC)" CFLAGS="$(OPT) $(CFLAGS)" TEST_JOBS="$(JOBS)" sh test/run.sh $(BUILD) "$(CXX)"

symbols: $(LIB)
	@bad=$$(nm -g --defined-only $(LIB) | awk 'NF==3 && $$2 ~ /[TDBRC]/ {print $$3}' | grep -v '^hfvis_' || true); \
	if [ -n "$$bad" ]; then echo "symbols: unprefixed exported symbols:"; echo "$$bad"; exit 1; fi; \
	echo "symbols: all exported symbols start with hfvis_"
cxx:
	$(CXX) -std=c++11 -Wall -Wextra -Werror -pedantic -fsyntax-only -I. test/cxx_header.cpp

# make bench follows config= and opt= (default: the release build, build/bench).
# Its "tiles" section runs the hfvis tool (HFVIS_CLI) whole and tiled: make bench BENCH_ARGS=tiles;
# its "threads" section runs it with --threads 1 and the online cores (HFVIS_BENCH_THREADS_N=4096
# for 4096^2, HFVIS_BENCH_THREADS_RUNS=3 for the minimum of 3 runs): make bench BENCH_ARGS=threads.
bench:
	@$(MAKE) --no-print-directory $(BENCH) $(CLI)
	@HFVIS_CLI=$(CLI) HFVIS_BENCH_GRASS=examples/bench/solar_grass.sh $(BENCH) $(BENCH_ARGS)

demo: 
	@$(MAKE) --no-print-directory config=release all
	@mkdir -p out
	@for e in $(patsubst examples/%.c,build/examples/%,$(wildcard examples/*.c)); do \
	  echo "demo: $$e"; $$e out || exit 1; done
	@echo "demo: gallery written to out/"; ls out

update-golden:
	@$(MAKE) --no-print-directory config=test $(TESTS)
	@for t in $(TESTS); do $$t --update-golden || exit 1; done

fuzz:
	@mkdir -p build/fuzz
	@for f in $(FUZZERS); do \
	  $(FUZZ_CC) -std=c99 -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all -I. test/fuzz/$$f.c hfvis.c ssao.c voxel.c -lm -o build/fuzz/$$f || exit 1; \
	  mkdir -p build/fuzz/corpus_$$f; \
	  build/fuzz/$$f -max_total_time=$(FUZZ_SECONDS) -max_len=4096 build/fuzz/corpus_$$f test/fuzz/seeds/$${f#fuzz_} || exit 1; \
	done

# The version in hfvis.pc is read from hfvis.h's HFVIS_VERSION_MAJOR/MINOR/PATCH. DESTDIR stages
# the files (packaging); the .pc file names PREFIX, where they end up.
HFVIS_VERSION_STRING := $(shell awk 'NF >= 3 && $$1 ~ /define$$/ && $$2 ~ /^HFVIS_VERSION_(MAJOR|MINOR|PATCH)$$/ { v = v s $$3; s = "." } END { print v }' hfvis.h)
install: $(LIB)
	mkdir -p '$(DESTDIR)$(PREFIX)/include' '$(DESTDIR)$(PREFIX)/lib/pkgconfig'
	cp hfvis.h '$(DESTDIR)$(PREFIX)/include/'
	cp $(LIB) '$(DESTDIR)$(PREFIX)/lib/'
	printf 'prefix=%s\nincludedir=$${prefix}/include\nlibdir=$${prefix}/lib\n\nName: hfvis\nDescription: height-field and screen-space visibility reference\nVersion: %s\nCflags: -I$${includedir}\nLibs: -L$${libdir} -lhfvis -lm\n' '$(PREFIX)' '$(HFVIS_VERSION_STRING)' > '$(DESTDIR)$(PREFIX)/lib/pkgconfig/hfvis.pc'
uninstall:
	rm -f '$(DESTDIR)$(PREFIX)/include/hfvis.h' '$(DESTDIR)$(PREFIX)/lib/libhfvis.a' '$(DESTDIR)$(PREFIX)/lib/pkgconfig/hfvis.pc'

clean:
	rm -rf build out

# make gallery: the release examples, then docs/gallery/*.png (README's Gallery) picked from the
# PNGs they write (examples/gallery.sh). The PNG writer is examples/png_write.h, included by common.h.
.PHONY: gallery
gallery:
	@$(MAKE) --no-print-directory config=release all
	@sh examples/gallery.sh build docs/gallery
$(EXAMPLES) $(CLI) $(BENCH): examples/png_write.h examples/zio.h examples/raster_io.h
$(BUILD)/test/test_png: examples/png_write.h examples/zio.h examples/common.h
$(BUILD)/test/test_raster_io: examples/raster_io.h examples/zio.h

# The portability matrix (test/portability.sh): make test with gcc and clang at -O0 and -O2 and with
# tcc, -DHFVIS_NO_STDIO per compiler, hfvis.h as C++98/11/17; absent compilers are skipped.
.PHONY: uninstall portability
portability:
	@sh test/portability.sh

# make valgrind: the test build's test programs, examples and CLI script under valgrind memcheck
# (errors and definite/indirect leaks fail); the last line is "valgrind: N programs, ...".
# VALGRIND_ONLY="test_x 06_lava cli" runs only those programs.
.PHONY: valgrind run-valgrind
valgrind:
	@$(MAKE) --no-print-directory config=test werror=1 run-valgrind
run-valgrind: $(TESTS) $(EXAMPLES) $(CLI)
	@sh test/valgrind.sh $(BUILD) $(VALGRIND_ONLY)

# make determinism: release builds with gcc (build/gcc) and clang (build/clang); every CLI command
# and example twice per build (bit-identical) and gcc against clang (test/determinism.sh).
.PHONY: determinism
determinism:
	@$(MAKE) --no-print-directory config=release werror=1 CC=gcc BUILD=build/gcc all build/gcc/test/imgdiff
	@$(MAKE) --no-print-directory config=release werror=1 CC=clang BUILD=build/clang all build/clang/test/imgdiff
	@sh test/determinism.sh build/gcc build/clang

# make fuzz-coverage: line coverage of each decoder by the corpus `make fuzz` left in build/fuzz
# plus the seeds (clang source-based coverage; test/fuzz/coverage.sh).
.PHONY: fuzz-coverage
fuzz-coverage:
	@sh test/fuzz/coverage.sh

# make solar-rsun: hfvis_solar_irradiation against GRASS r.sun on flat ground and 30 deg planes,
# 4 latitudes x 4 days (test/solar_rsun.sh, about 2 minutes: not part of make test); SKIPs
# without `grass` (Debian: grass-core).
.PHONY: solar-rsun
solar-rsun:
	@CC="$(CC)" sh test/solar_rsun.sh
# make solar-ephem: hfvis_spa against PyEphem (an independent implementation) over 2000 instants
# and places, both hemispheres, polar day and night (test/solar_ephem.sh, under a minute); SKIPs
# without python3's ephem (Debian: python3-ephem). make solar-check runs the three comparisons.
# make solar-rsun-dem: hfvis solar against r.sun with its own shadowing on the Colorado SRTM tile
# and a 400^2 crop of the Slovenian lidar DTM, days 172 and 355, with experiments that explain
# the differences (test/solar_rsun_dem.sh, about 22 minutes); the DEMs come from
# HFVIS_BENCH_DEMS, as for make bench; SKIPs without them or without `grass`.
.PHONY: solar-ephem solar-check solar-rsun-dem
solar-ephem:
	@CC="$(CC)" sh test/solar_ephem.sh
solar-rsun-dem: $(CLI)
	@HFVIS_CLI=$(CLI) sh test/solar_rsun_dem.sh
solar-check: solar-ephem solar-rsun solar-rsun-dem
