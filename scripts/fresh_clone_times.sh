#!/usr/bin/env bash
# How long a newcomer waits: a fresh clone of this repository's HEAD, with no pip cache and a
# cargo home of its own (every crate downloaded and compiled, cargo-fuzz installed), runs
# `make demo` (the time to its first scene's result, and to its end), then each part of
# `make test` timed apart (docs/DEVELOPING.md).
#
#   scripts/fresh_clone_times.sh [demo|test|both] [DIR]
#
# DIR (default a new directory under /tmp) holds the clone, the cargo home and the logs; the
# figures go to DIR/times.txt, one line a part: wall seconds, CPU seconds, exit code.
set -euo pipefail

what=${1:-both}
case $what in demo | test | both) ;; *)
	echo "usage: $0 [demo|test|both] [DIR]: '$what' is not one of demo, test, both" >&2
	exit 2
	;;
esac
root=$(git -C "$(dirname "$0")/.." rev-parse --show-toplevel)
dir=${2:-$(mktemp -d /tmp/gearrattle-fresh.XXXXXX)}
mkdir -p "$dir"
times=$dir/times.txt
: >"$times"

export PIP_NO_CACHE_DIR=1 CARGO_HOME=$dir/cargo-home
# The toolchains stay rustup's; the registry, the git cache and installed tools are new.
mkdir -p "$CARGO_HOME"

# $1: a label; the rest: the command, run in the clone with its output in DIR/<label>.log.
timed() {
	local label=$1
	shift
	local t0 rc=0
	t0=$(date +%s.%N)
	/usr/bin/time -f '%U %S' -o "$dir/cpu" "$@" >"$dir/$label.log" 2>&1 || rc=$?
	awk -v l="$label" -v t0="$t0" -v t1="$(date +%s.%N)" -v rc="$rc" '
		{ printf "%-16s wall %6.0f s  cpu %6.0f s  rc %s\n", l, t1 - t0, $1 + $2, rc }' "$dir/cpu" |
		tee -a "$times"
}

clone() {
	rm -rf "$dir/clone"
	git clone -q "$root" "$dir/clone"
	cd "$dir/clone"
}

if [[ $what != test ]]; then
	clone
	t0=$(date +%s)
	# The first result: the first scene's summary line of the demo's output.
	(until grep -q '^=== S1' "$dir/demo.log" 2>/dev/null; do sleep 1; done
		echo "demo-first      wall $(($(date +%s) - t0)) s (the first scene's result printed)" |
			tee -a "$times") &
	watcher=$!
	timed demo make demo
	kill "$watcher" 2>/dev/null || true
	# The demo's own figures: what the clone built, for `make test` to start from scratch.
	rm -rf "$dir/cargo-home/registry" "$dir/clone"
fi

if [[ $what != demo ]]; then
	clone
	export CI=true
	timed setup make setup
	for part in $(make -s -f Makefile -f - print-test-targets <<<'print-test-targets: ; @echo $(TEST_TARGETS)'); do
		# fmu apart from test-python, whose prerequisite it is.
		[[ $part == test-python ]] && timed fmu make fmu
		timed "$part" make "$part"
	done
fi
echo "figures in $times"
