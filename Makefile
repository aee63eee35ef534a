# wobble: the only build system. `make demo` and `make test` are the two set-up commands.
CC      ?= gcc
BUILD   ?= build
PREFIX  ?= /usr/local
OPT     ?= -O2
# Debian packages the build and the tests need; `make deps` installs the missing ones
PKGS    := gcc make libc6-dev pkg-config liblua5.4-dev libcjson-dev libassimp-dev libosmesa6-dev \
           libstb-dev ffmpeg tetgen libglfw3-dev xvfb xdotool parallel
# installed by `make bench` (the Bullet peer) and `make test-cluster` (a one-node Slurm) alone
BENCH_PKGS   := g++ libbullet-dev
CLUSTER_PKGS := slurm-wlm munge
PCMODS  := lua5.4 libcjson assimp osmesa glfw3
# shell code setting `missing` to the packages of PKGS that are not installed ("ii";
# a removed package whose configuration files remain is not); dpkg-query is quick
MISSING  = missing=""; for p in $(PKGS); do \
	     dpkg-query -W -f='$${db:Status-Abbrev}' $$p 2>/dev/null | grep -q '^ii' || missing="$$missing $$p"; done

CFLAGS_BASE := -std=c11 $(OPT) -g -Wall -Wextra -Werror -pthread -fno-math-errno -ffp-contract=off -D_GNU_SOURCE -Isrc \
               -DWB_ROOT='"$(CURDIR)"' -DWB_PREFIX='"$(PREFIX)"'
CFLAGS  += $(CFLAGS_BASE) $(EXTRA_CFLAGS)
LDFLAGS += -pthread $(EXTRA_LDFLAGS)
PC_CFLAGS = $(shell pkg-config --cflags $(PCMODS) 2>/dev/null)
PC_LIBS   = $(shell pkg-config --libs $(PCMODS) 2>/dev/null)

# one folder per layer (docs/architecture.md, "Layers"): cli -> lua -> {render, io} -> core -> wobble.h
LAYERS   := core io render lua cli
# the core: no Lua, no GL, no file formats, no command line
CORE_SRC := $(wildcard src/core/*.c)
APP_SRC  := $(foreach l,io render lua cli,$(wildcard src/$(l)/*.c))
HEADERS  := $(wildcard src/*.h src/*/*.h)
CORE_OBJ := $(CORE_SRC:src/%.c=$(BUILD)/obj/%.o)
APP_OBJ  := $(APP_SRC:src/%.c=$(BUILD)/obj/%.o)
UNIT_SRC := $(wildcard tests/unit/*.c)

.PHONY: all build deps check-deps test asan bench demo install clean mutate fuzz fuzz-build test-cluster
all: check-deps
	@$(MAKE) --no-print-directory build

build: $(BUILD)/libwobble.a $(BUILD)/wobble $(BUILD)/unit_tests

# quiet when every package is there; without dpkg (not Debian) the libraries are
# looked up with pkg-config instead
check-deps:
	@if command -v dpkg-query >/dev/null 2>&1; then $(MISSING); [ -z "$$missing" ]; \
	else pkg-config --exists $(PCMODS) 2>/dev/null; fi || $(MAKE) --no-print-directory deps

# apt's output (about 1,400 lines for a fresh system) goes whole to $(DEPS_LOG) (its tail
# shown when it fails); its progress is shown as it works (mk/apt_progress.awk: one
# updating line on a terminal, a line each 10% elsewhere). Without root and without sudo
# it says what to run instead. A pipe hides apt-get's exit status from sh (no pipefail in
# dash), so it is passed through $(DEPS_LOG).rc
DEPS_LOG = $(BUILD)/deps.log
APT_STEP = { $$SUDO env DEBIAN_FRONTEND=noninteractive apt-get -o APT::Status-Fd=1 $(1) 2>&1; echo $$? >$(DEPS_LOG).rc; } \
	   | tee -a $(DEPS_LOG) | awk -v tty=$$tty -f mk/apt_progress.awk; [ "$$(cat $(DEPS_LOG).rc)" = 0 ]
deps:
	@$(MISSING); \
	if [ -z "$$missing" ]; then echo "all Debian packages present"; exit 0; fi; \
	if [ "$$(id -u)" = 0 ]; then SUDO=; \
	elif command -v sudo >/dev/null 2>&1; then SUDO=sudo; \
	else echo "wobble needs these Debian packages:$$missing" >&2; \
	  echo "run as root (su -), then make again: apt-get update && apt-get install -y$$missing" >&2; exit 1; fi; \
	tty=0; [ -t 1 ] && tty=1; \
	mkdir -p $(BUILD) && : >$(DEPS_LOG); \
	echo "installing Debian packages:$$missing"; \
	echo "  (apt-get's whole output: $(DEPS_LOG); a fresh system takes a few minutes)"; \
	echo "  apt-get update: reading the package lists"; \
	if $(call APT_STEP,update -q) && \
	  echo "  apt-get install: the packages above and what they need" && \
	  $(call APT_STEP,install -y -q $$missing); then \
	  rm -f $(DEPS_LOG).rc; echo "installed:$$missing"; \
	else rm -f $(DEPS_LOG).rc; echo "apt-get failed; the end of its output ($(DEPS_LOG)):" >&2; tail -n 20 $(DEPS_LOG) >&2; exit 1; fi

# short build lines (CC src/core/bend.c, LD build/wobble); `make V=1` shows the commands;
# `make -s` neither (its flag letters are MAKEFLAGS' first word)
V ?= 0
ifeq ($(V),1)
  quiet =
else ifneq ($(findstring s,$(firstword -$(MAKEFLAGS))),)
  quiet = @
else
  quiet = @printf '  %-4s %s\n' $(1) $(2);
endif

# each object lists the headers it really includes in its .d (-MMD; -MP: a deleted header
# is no error), so touching a header rebuilds its dependents only. An object without its
# .d (a build from before) is rebuilt once: the empty rule makes a missing .d a new one
$(BUILD)/obj/%.o: src/%.c $(BUILD)/obj/%.d | $(addprefix $(BUILD)/obj/,$(LAYERS))
	$(call quiet,CC,$<)$(CC) $(CFLAGS) $(PC_CFLAGS) -MMD -MP -c $< -o $@
DEPS := $(CORE_OBJ:.o=.d) $(APP_OBJ:.o=.d)
$(DEPS):
include $(wildcard $(DEPS))

$(addprefix $(BUILD)/obj/,$(LAYERS)):
	@mkdir -p $@

$(BUILD)/libwobble.a: $(CORE_OBJ)
	$(call quiet,AR,$@)ar rcs $@ $^

$(BUILD)/wobble: $(APP_OBJ) $(BUILD)/libwobble.a
	$(call quiet,LD,$@)$(CC) $(LDFLAGS) -o $@ $(APP_OBJ) $(BUILD)/libwobble.a $(PC_LIBS) -lm

# C unit tests of the core alone: links only libwobble.a
$(BUILD)/unit_tests: $(UNIT_SRC) $(wildcard tests/unit/*.h) $(BUILD)/libwobble.a
	$(call quiet,CCLD,$@)$(CC) $(CFLAGS) -o $@ $(UNIT_SRC) $(BUILD)/libwobble.a $(LDFLAGS) -lm

test: check-deps
	@$(MAKE) --no-print-directory build
	@sh tests/run_all.sh $(BUILD)

asan: check-deps
	@$(MAKE) --no-print-directory BUILD=build-asan OPT=-O1 \
	  EXTRA_CFLAGS="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined" \
	  EXTRA_LDFLAGS="-fsanitize=address,undefined" build
	@ASAN_OPTIONS=detect_leaks=1 LSAN_OPTIONS=suppressions=$(CURDIR)/tests/render/lsan.supp:print_suppressions=0 \
	  sh tests/run_all.sh build-asan

# mutation testing: each rule of tests/mutate/mutations.txt applied alone to a scratch
# copy of the tree, its part of the suite run; fails below a 90% kill rate
mutate: check-deps
	@sh tests/mutate/run.sh $(MUTATIONS)

# the benchmark (docs/benchmark.md; tests/bench/run.sh): the double build, a WB_FLOAT
# build beside it and the Bullet peer, each scene in a process of its own; BENCH_PKGS are
# installed by it alone. JSON=FILE: every row as a JSON line too
BENCH_OPT := -O3 -march=native
bench: check-deps
	@$(MAKE) --no-print-directory check-deps PKGS="$(BENCH_PKGS)"
	@$(MAKE) --no-print-directory OPT="$(BENCH_OPT)" BUILD=build-bench build build-bench/bullet_cloth
	@$(MAKE) --no-print-directory OPT="$(BENCH_OPT)" BUILD=build-bench-float EXTRA_CFLAGS=-DWB_FLOAT build-bench-float/wobble
	@sh tests/bench/run.sh build-bench build-bench-float $(JSON)

# the Bullet peer: Bullet's headers as system headers (they do not pass -Wextra -Werror)
$(BUILD)/bullet_cloth: tests/bench/bullet_cloth.cpp
	@mkdir -p $(BUILD)
	$(call quiet,CXX,$@)g++ -std=c++11 $(BENCH_OPT) -Wall -Wextra -Werror $(patsubst -I%,-isystem %,$(shell pkg-config --cflags bullet)) \
	  -o $@ $< $(shell pkg-config --libs bullet)

# the clothesline, 6 s at 1280x720 with every layer, as an H.264 video
demo: check-deps
	@$(MAKE) --no-print-directory build
	@mkdir -p out
	$(BUILD)/wobble run scripts/cloth_clothesline.lua --set seconds=6 --record out/clothesline.mp4
	@echo "demo video: $(CURDIR)/out/clothesline.mp4"

install: all
	install -d $(DESTDIR)$(PREFIX)/bin $(DESTDIR)$(PREFIX)/share/wobble/lua/wobble
	install -m 755 $(BUILD)/wobble $(DESTDIR)$(PREFIX)/bin/wobble
	install -m 644 lua/wobble/*.lua $(DESTDIR)$(PREFIX)/share/wobble/lua/wobble/
	install -m 644 -D -t $(DESTDIR)$(PREFIX)/share/wobble/bench tests/bench/*.lua
	install -d $(DESTDIR)$(PREFIX)/lib $(DESTDIR)$(PREFIX)/include
	install -m 644 $(BUILD)/libwobble.a $(DESTDIR)$(PREFIX)/lib/
	install -m 644 src/wobble.h $(DESTDIR)$(PREFIX)/include/

# build folders only: out/ holds the user's videos and results
clean:
	rm -rf build build-asan build-bench build-bench-float build-fuzz $(BUILD)

# ---- fuzzing (docs/testing.md, "Fuzzing"): `make fuzz` runs each libFuzzer target FUZZ_TIME
# seconds; FUZZ_PKGS are installed by it alone, never by `make test`
FUZZ_PKGS    := clang libclang-rt-14-dev
FUZZ_TIME    ?= 60
FUZZ_CC      ?= clang
FUZZ_BUILD   := build-fuzz
FUZZ_TARGETS := json mesh mesh_obj
FUZZ_SAN     := -fsanitize=address,undefined -fno-sanitize-recover=undefined
FUZZ_CFLAGS  := -std=c11 -O1 -g -fno-omit-frame-pointer -pthread -fno-math-errno -ffp-contract=off -D_GNU_SOURCE -Isrc -Wall -Wextra
FUZZ_SRC     := $(CORE_SRC) $(wildcard src/io/*.c)
FUZZ_OBJ     := $(FUZZ_SRC:src/%.c=$(FUZZ_BUILD)/obj/%.o)
# the same targets under gcc, run once per file of the corpus by tests/fuzz/replay.sh
FUZZ_REPLAY  := $(FUZZ_TARGETS:%=$(BUILD)/fuzz_%_replay)
IO_OBJ        = $(filter $(BUILD)/obj/io/%,$(APP_OBJ))
fuzz_def      = $(if $(filter mesh_obj,$(1)),-DFUZZ_FORMAT='"obj"')
fuzz_src      = tests/fuzz/fuzz_$(if $(filter mesh_obj,$(1)),mesh,$(1)).c
build: $(FUZZ_REPLAY)

$(BUILD)/fuzz_%_replay: tests/fuzz/fuzz_json.c tests/fuzz/fuzz_mesh.c tests/fuzz/replay.c $(IO_OBJ) $(BUILD)/libwobble.a
	$(call quiet,CCLD,$@)$(CC) $(CFLAGS) $(PC_CFLAGS) $(call fuzz_def,$*) -o $@ $(call fuzz_src,$*) tests/fuzz/replay.c \
	  $(IO_OBJ) $(BUILD)/libwobble.a $(LDFLAGS) $(PC_LIBS) -lm

$(FUZZ_BUILD)/obj/%.o: src/%.c $(FUZZ_BUILD)/obj/%.d
	@mkdir -p $(dir $@)
	$(call quiet,CC,$<)$(FUZZ_CC) $(FUZZ_CFLAGS) -fsanitize=fuzzer-no-link $(FUZZ_SAN) $(PC_CFLAGS) -MMD -MP -c $< -o $@
FUZZ_DEPS := $(FUZZ_OBJ:.o=.d)
$(FUZZ_DEPS):
include $(wildcard $(FUZZ_DEPS))

$(FUZZ_BUILD)/fuzz_%: tests/fuzz/fuzz_json.c tests/fuzz/fuzz_mesh.c $(FUZZ_OBJ)
	$(call quiet,CCLD,$@)$(FUZZ_CC) $(FUZZ_CFLAGS) -fsanitize=fuzzer $(FUZZ_SAN) $(PC_CFLAGS) $(call fuzz_def,$*) -o $@ \
	  $(call fuzz_src,$*) $(FUZZ_OBJ) $(PC_LIBS) -lm

fuzz-build: $(FUZZ_TARGETS:%=$(FUZZ_BUILD)/fuzz_%)

# new inputs go to build-fuzz/corpus/T (the seeds in tests/fuzz/corpus/T stay as they
# are), crashes to build-fuzz/crash-T-*: add those to tests/fuzz/regress/T once fixed.
# fuzz_mesh_obj ignores leaks: assimp leaks on its own error paths, and the suppression
# (tests/fuzz/lsan.supp, used by the replay) needs full malloc stacks, too slow here
fuzz: check-deps
	@$(MAKE) --no-print-directory check-deps PKGS="$(FUZZ_PKGS)"
	@$(MAKE) --no-print-directory fuzz-build
	@for t in $(FUZZ_TARGETS); do \
	  mkdir -p $(FUZZ_BUILD)/corpus/$$t; \
	  dict=; [ -f tests/fuzz/$$t.dict ] && dict=-dict=tests/fuzz/$$t.dict; \
	  echo "== fuzz_$$t for $(FUZZ_TIME) s"; \
	  leaks=1; [ $$t = mesh_obj ] && leaks=0; \
	  ASAN_OPTIONS=detect_leaks=$$leaks $(FUZZ_BUILD)/fuzz_$$t -detect_leaks=$$leaks -max_total_time=$(FUZZ_TIME) -timeout=10 -rss_limit_mb=2048 -max_len=4096 \
	    -print_final_stats=1 -artifact_prefix=$(FUZZ_BUILD)/crash-$$t- $$dict \
	    $(FUZZ_BUILD)/corpus/$$t tests/fuzz/corpus/$$t tests/fuzz/regress/$$t || exit 1; \
	done

# tests/cli/replay.sh: the input recorder (src/lua/input.h) has no Lua entry point, so a
# small program drives it as the viewer does, linked with the app's objects but main.c
DRIVER_OBJ = $(filter-out $(BUILD)/obj/cli/%,$(APP_OBJ))
build: $(BUILD)/input_driver
$(BUILD)/input_driver: tests/cli/input_driver.c $(DRIVER_OBJ) $(BUILD)/libwobble.a $(HEADERS)
	$(call quiet,CCLD,$@)$(CC) $(CFLAGS) $(PC_CFLAGS) -o $@ tests/cli/input_driver.c $(DRIVER_OBJ) $(BUILD)/libwobble.a \
	  $(LDFLAGS) $(PC_LIBS) -lm
# tests/cli/budget.sh: the peak resident memory of a run's whole process tree
build: $(BUILD)/treepeak
$(BUILD)/treepeak: tests/cli/treepeak.c
	$(call quiet,CCLD,$@)$(CC) $(CFLAGS) -o $@ $< $(LDFLAGS)
# ---- a one-node Slurm (docs/cli.md, "Sweeps"): `make test-cluster` starts munged, slurmctld and
# slurmd in a temporary folder, runs a sweep's job array through sbatch and collects it;
# CLUSTER_PKGS are installed by it alone, never by `make test`; needs root
test-cluster: check-deps
	@$(MAKE) --no-print-directory check-deps PKGS="$(CLUSTER_PKGS)"
	@$(MAKE) --no-print-directory build
	@sh tests/cluster/run.sh $(BUILD)
