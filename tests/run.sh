#!/usr/bin/env bash
# run.sh: the test suite, on lavapipe with the Vulkan validation layer on, as a pool of jobs:
# the C unit tests in groups (one job a unit-test suite's fast tests, one a slow test) and
# the shell scripts of tests/regress (each runs the checks of the tiers asked for: lib.sh).
#   tests/run.sh [--tier fast|slow|full] [-j N] [--stop] [--list] [NAME...]
# --tier fast (the default; make test) runs the fast tier, slow (make test-slow) the slow one
# alone, full (make test-full) both. -j N runs N jobs at once (default: the number of CPUs,
# $TEST_JOBS); each job's output is kept and printed whole, in a fixed order, with its time.
# NAME runs only the jobs whose name contains it (unit/brdf, regress/path.sh, path...).
# --stop ends the run at the first job that fails (tests/mutants.sh). --list prints the
# jobs and runs nothing. tests/README.md says which tier a test belongs to.
# Environment: GONIO (the program), UNIT (the unit-test binary), TESTTOOL, CONFIG (build config).
set -u
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
cd "$root"

tier=fast
jobs_max=${TEST_JOBS:-$(nproc 2>/dev/null || echo 2)}
list=0
stop=0
only=()
while [ $# -gt 0 ]; do
    case $1 in
        --tier) tier=${2:-}; shift 2 ;;
        --tier=*) tier=${1#*=}; shift ;;
        -j) jobs_max=${2:-}; shift 2 ;;
        -j*) jobs_max=${1#-j}; shift ;;
        --list) list=1; shift ;;
        --stop) stop=1; shift ;;
        -h | --help) sed -n '2,12p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
        -*) echo "run.sh: unknown option $1" >&2; exit 2 ;;
        *) only+=("$1"); shift ;;
    esac
done
case $tier in fast | slow | full) ;; *) echo "run.sh: --tier fast, slow or full, not '$tier'" >&2; exit 2 ;; esac
case $jobs_max in '' | *[!0-9]* | 0) echo "run.sh: -j takes a positive number" >&2; exit 2 ;; esac

export GONIO=${GONIO:-build/release/gonio} UNIT=${UNIT:-build/release/unit_tests}
export TESTTOOL=${TESTTOOL:-build/release/testtool} CONFIG=${CONFIG:-release}
export GONIO=$(realpath "$GONIO") UNIT=$(realpath "$UNIT") TESTTOOL=$(realpath "$TESTTOOL")
# Every Vulkan instance the tests create validates; any message fails that run.
export GONIO_VALIDATE=1
# Tests run on lavapipe, the device every developer machine and CI has.
export VK_ICD_FILENAMES=${VK_ICD_FILENAMES:-$(ls /usr/share/vulkan/icd.d/lvp_icd*.json | head -n 1)}
export GONIO_ASSETS=${GONIO_ASSETS:-$root/../shared/assets}
# Mesa and LLVM keep some allocations until exit; the suppressions name only those.
export LSAN_OPTIONS="suppressions=$here/lsan.supp:print_suppressions=0"
# A small quarantine: lavapipe allocates and frees a lot, and the default 256 MB makes
# every run page-fault its way through it (4x slower).
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:quarantine_size_mb=16"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-$(mktemp -d)}
export TEST_TMP=$(mktemp -d)
# Fixtures that several scripts share (lib.sh's fixture): made once a run, by the first
# script that asks for one.
export TEST_FIXTURES=$TEST_TMP/fixtures
mkdir -p "$TEST_FIXTURES"
# The run's own Mesa shader cache: every kernel variant is compiled by LLVM once a run and
# read back by the run's other processes, and a run takes as long on a fresh machine as on
# one whose cache is warm (docs/performance.md). MESA_SHADER_CACHE_DIR set outside wins.
export MESA_SHADER_CACHE_DIR=${MESA_SHADER_CACHE_DIR:-$TEST_TMP/mesa-shader-cache}
export GONIO_TEST_TIER=$tier
# The fast tier runs lavapipe's kernels without LLVM's optimisation passes (GALLIVM_PERF=nopt):
# its renders are small, so compiling a kernel variant costs more than running it, and nopt
# compiles in about half the time and runs about 40 % slower (docs/performance.md). The slow
# tier keeps the optimised kernels (make test-full runs every check so). GALLIVM_PERF set
# outside (even empty) wins.
[ -n "${GALLIVM_PERF+x}" ] && gallivm_outside=1
[ "$tier" = fast ] && export GALLIVM_PERF=${GALLIVM_PERF-nopt}
# ... but for the jobs whose kernels run far longer than they compile, which take less CPU
# optimised (unit/brdf: its BRDF kernels evaluate millions of queries; 61 s of CPU against
# 71 with nopt, docs/performance.md).
optimised_jobs=" unit/brdf "
# The jobs run side by side, as many as there are CPUs, so lavapipe's own threads would only
# contend with the other jobs for them: one each (LP_NUM_THREADS set outside wins).
export LP_NUM_THREADS=${LP_NUM_THREADS-1}

# ---- the jobs ------------------------------------------------------------------------------
# job_name[i], job_cmd[i] (an argument list, joined by the unit separator \037)
job_name=()
job_cmd=()
add_job() { # add_job NAME COMMAND ARGS...
    local name=$1; shift
    if [ ${#only[@]} -gt 0 ]; then
        local o hit=0
        for o in "${only[@]}"; do case $name in *"$o"*) hit=1 ;; esac; done
        [ $hit = 1 ] || return 0
    fi
    job_name+=("$name")
    local IFS=$'\037'
    job_cmd+=("$*")
}
unit_tier=$tier
[ "$tier" = full ] && unit_tier=all
# Unit tests: a job for each suite's fast tests, and one for each slow test.
if ! unit_list=$("$UNIT" --list --tier "$unit_tier"); then
    echo "run.sh: $UNIT --list failed" >&2
    exit 1
fi
prev=
while read -r test t; do
    [ -n "$test" ] || continue
    if [ "$t" = slow ]; then
        add_job "unit/$test" "$UNIT" --tier slow "^$test"
    elif [ "${test%%.*}" != "$prev" ]; then
        prev=${test%%.*}
        add_job "unit/$prev" "$UNIT" --tier fast "^$prev."
    fi
done <<<"$unit_list"
# Regression scripts: each in the fast tier; in the slow one, those with slow checks
# (lib.sh: in_tier slow), which run only those then.
for t in tests/regress/*.sh; do
    [ "$tier" != slow ] || grep -q 'in_tier slow' "$t" || continue
    add_job "regress/$(basename "$t")" "$t"
done
n=${#job_name[@]}
if [ $list = 1 ]; then
    printf '%s\n' "${job_name[@]}"
    exit 0
fi
if [ "$n" = 0 ]; then
    echo "run.sh: no job matches ${only[*]}" >&2
    exit 2
fi

jobdir=$TEST_TMP/jobs
mkdir -p "$jobdir"
pids=()
cleanup() {
    local p
    for p in "${pids[@]}"; do [ -n "$p" ] && kill -TERM -- "-$p" "$p" 2>/dev/null; done
    rm -rf "$TEST_TMP"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# Start order: longest first, by the times the last run in this build tree took (kept
# beside the unit-test binary), else by tests/job-times (typical times on 2 cores, so that a
# fresh clone's first run starts its long jobs first too); a job timed in neither goes
# first. The printed order is fixed.
times_file=$(dirname "$UNIT")/test-times
declare -A last_time=() typical_time=()
if [ -r "$here/job-times" ]; then
    while read -r name secs; do [ -n "$name" ] && [ "${name#\#}" = "$name" ] && typical_time[$name]=$secs; done <"$here/job-times"
fi
if [ -r "$times_file" ]; then
    while read -r name secs; do last_time[$name]=$secs; done <"$times_file"
fi
order=$(for ((i = 0; i < n; i++)); do echo "${last_time[${job_name[i]}]:-${typical_time[${job_name[i]}]:-9999}} $i"; done | sort -k1,1nr -k2,2n | cut -d' ' -f2)
order=($order)

# run_job I: runs job I with its output in $jobdir/I.out; writes its status and seconds.
run_job() {
    local i=$1 t0=$EPOCHREALTIME rc
    local IFS=$'\037'
    local cmd=(${job_cmd[i]})
    case $optimised_jobs in *" ${job_name[i]} "*) [ -n "${gallivm_outside+x}" ] || local GALLIVM_PERF= ;; esac
    "${cmd[@]}" >"$jobdir/$i.out" 2>&1 </dev/null
    rc=$?
    # times' second line: the CPU time of this job's processes (user, system), as 1m2.345s
    # (written to a file: in a command substitution it would be another process's)
    times >"$jobdir/$i.times"
    local cpu=$(tail -n 1 "$jobdir/$i.times" | awk '{ for (i = 1; i <= 2; i++) { split($i, a, "m"); s += 60 * a[1] + a[2] } printf "%.1f", s }')
    echo "$rc $(awk -v a="$t0" -v b="$EPOCHREALTIME" 'BEGIN { printf "%.1f", b - a }') $cpu" >"$jobdir/$i.done"
}

echo "tests: the $tier tier, $n jobs, $jobs_max at a time ($CONFIG build)"
if [ ! -d "$GONIO_ASSETS" ]; then
    echo "note: $GONIO_ASSETS is absent: the tests that need third-party assets will skip"
fi
run_t0=$EPOCHREALTIME
passed=0 failed=0 skipped=0 printed=0 next=0 running=0 any_failed=0
failed_names=()
declare -A started=()
# print_done: prints, in the fixed order, every finished job not printed yet up to the
# first one still running.
print_job() { # print_job I: job I's output and verdict; counts it
    local i=$1 rc secs cpu verdict name=${job_name[$1]}
    read -r rc secs cpu <"$jobdir/$i.done"
    echo "== $name"
    cat "$jobdir/$i.out"
    case $rc in
        0) verdict=passed; passed=$((passed + 1)) ;;
        77) verdict=skipped; skipped=$((skipped + 1)) ;;
        *) verdict="FAILED (exit $rc)"; failed=$((failed + 1)); failed_names+=("$name") ;;
    esac
    echo "-- $name: $verdict in $secs s (CPU $cpu s)"
    echo "$name $secs $cpu" >>"$jobdir/times"
}
print_done() {
    while [ $printed -lt $n ] && [ -e "$jobdir/$printed.done" ]; do
        print_job $printed
        printed=$((printed + 1))
    done
}
while [ $printed -lt $n ]; do
    while [ $running -lt "$jobs_max" ] && [ $next -lt $n ]; do
        i=${order[next]}
        next=$((next + 1))
        set -m # each job in a process group of its own, so that an interrupt ends it whole
        run_job "$i" &
        set +m
        pids[i]=$!
        started[$!]=$i
        running=$((running + 1))
    done
    if [ $running -gt 0 ]; then
        wait -n
        # wait -n says nothing of which job ended: count those whose .done exists.
        running=0
        for p in "${!started[@]}"; do
            i=${started[$p]}
            if [ -e "$jobdir/$i.done" ]; then
                wait "$p" 2>/dev/null
                unset "started[$p]"
                pids[i]=
                read -r rc _ <"$jobdir/$i.done"
                [ "$rc" = 0 ] || [ "$rc" = 77 ] || any_failed=1
            else
                running=$((running + 1))
            fi
        done
    fi
    print_done
    if [ $stop = 1 ] && [ $any_failed = 1 ]; then
        # --stop: end the jobs still running, print those that ended, start no more.
        for p in "${!started[@]}"; do kill -TERM -- "-$p" 2>/dev/null; wait "$p" 2>/dev/null; done
        for ((i = printed; i < n; i++)); do
            [ -e "$jobdir/$i.done" ] && print_job $i
        done
        echo "(--stop: a job failed; $((n - next)) jobs not started, those running stopped)"
        break
    fi
done
wall=$(awk -v a="$run_t0" -v b="$EPOCHREALTIME" 'BEGIN { printf "%.0f", b - a }')
# The slowest jobs first: where the time of a run goes.
echo "== job times, slowest first: wall and CPU seconds"
sort -k2,2nr "$jobdir/times" | awk '{ printf "  %7.1f %7.1f  %s\n", $2, $3, $1; cpu += $3 }
    END { printf "  CPU %.0f s in all\n", cpu }'
# Keep the times for the next run's start order (merged with those of jobs not run now).
{
    cut -d' ' -f1,2 "$jobdir/times"
    for name in "${!last_time[@]}"; do
        grep -q "^$name " "$jobdir/times" || echo "$name ${last_time[$name]}"
    done
} 2>/dev/null | sort >"$times_file.tmp" && mv "$times_file.tmp" "$times_file"
for name in "${failed_names[@]}"; do echo "FAILED: $name"; done
echo "tests ($tier tier, $CONFIG): $passed passed, $failed failed, $skipped skipped in $wall s"
[ "$failed" = 0 ]
