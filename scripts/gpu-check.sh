#!/usr/bin/env bash
# The first-GPU check: one script that, on a bare Linux machine with an NVIDIA GPU and
# its driver, CMake and a C compiler, and no package registry, builds rsmooth from this tree (or
# uses a carried build), provides the OpenCL ICD loader if the machine lacks one, lists the
# devices, runs the tests cl_vs_reference and cl_beyond with the GPU kernel variant, and times
# rsmooth-bench on 200k, 1M and 16M generated triangles and Bunny0.2, and --best on Bunny0.2,
# writing JSON into an output folder, all within a time budget (8 minutes by default).
#
#   scripts/gpu-check.sh --pack
#       here, on a Debian machine with ocl-icd-libopencl1, opencl-c-headers and libpng-dev: fills
#       the git-ignored folder .gpu-check/ (about 6 MB) with what a bare machine may lack: the ICD
#       loader libOpenCL.so.1, the OpenCL C headers, libpng and zlib (headers and libraries), and
#       the benchmark meshes' Noisy.obj from ../shared. Copy or carry .gpu-check with the tree.
#   scripts/gpu-check.sh [--device nvidia|pocl|SPEC] [--out DIR] [--build DIR] [--skip-build]
#                        [--budget S] [--cap-16m S] [--bunny FILE] [--jobs N]
#       the check (docs/maintainers/gpu.md says what it writes). Exit 0 when every step passed, 1 when one
#       failed or ran out of time (the summary names it), 2 on bad usage or set-up.
set -u -o pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
CARRY=$ROOT/.gpu-check
MODELS="Fandisk0.3 Block0.4 Bunny0.2 SharpSphere0.3 Twelve0.5Impulsive"

KIND=nvidia
OUT_DIR=${OUT:-}
BUILD=""
SKIP_BUILD=0
PACK=0
BUDGET=480
CAP_16M=180
BUNNY=""
JOBS=$(nproc 2>/dev/null || echo 2)

usage() {
    sed -n '2,20p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
    cat <<'EOF'

  --device KIND   nvidia (default): NVIDIA's OpenCL library alone, its first GPU;
                  pocl: PoCL alone, its CPU device (the rehearsal on a machine without a GPU);
                  anything else: the system's ICDs, passed on as RSMOOTH_DEVICE (gpu, cpu, P:D, NAME)
  --out DIR       where the JSON and the log go (default: $OUT)
  --build DIR     build folder (default: build-gpu-check; with --skip-build, the carried one)
  --skip-build    use the programs already in --build DIR (a carried build) instead of building
  --budget S      seconds for the whole check (default 480); each step gets what is left
  --cap-16m S     seconds at most for the 16M-triangle bench (default 180)
  --bunny FILE    Bunny0.2's Noisy.obj (default: ../shared/data/benchmark/Bunny0.2/Noisy.obj,
                  else .gpu-check/shared/..., else a generated mesh of the same size, said so)
  --jobs N        build jobs (default: the cores)
EOF
}

die() {
    echo "gpu-check: $*" >&2
    exit 2
}

while [ $# -gt 0 ]; do
    case $1 in
    --device) KIND=${2:?--device needs a value}; shift 2 ;;
    --out) OUT_DIR=${2:?--out needs a folder}; shift 2 ;;
    --build) BUILD=${2:?--build needs a folder}; shift 2 ;;
    --skip-build) SKIP_BUILD=1; shift ;;
    --pack) PACK=1; shift ;;
    --budget) BUDGET=${2:?}; shift 2 ;;
    --cap-16m) CAP_16M=${2:?}; shift 2 ;;
    --bunny) BUNNY=${2:?}; shift 2 ;;
    --jobs) JOBS=${2:?}; shift 2 ;;
    -h | --help) usage; exit 0 ;;
    *) usage >&2; die "unknown argument: $1" ;;
    esac
done
case $BUDGET$CAP_16M$JOBS in *[!0-9]*) die "--budget, --cap-16m and --jobs take whole numbers" ;; esac

# --- --pack: what a bare machine may lack, into .gpu-check/ (run here, not there) ---------------
# The first path of NAME in the dynamic linker's cache.
cached_library() { ldconfig -p 2>/dev/null | awk -v n="$1" '$1 == n { print $NF; exit }'; }

if [ $PACK = 1 ]; then
    rm -rf "$CARRY"
    mkdir -p "$CARRY/lib" "$CARRY/include/CL" || die "cannot make $CARRY"
    loader=$(cached_library libOpenCL.so.1)
    [ -n "$loader" ] || die "--pack: no libOpenCL.so.1 here (apt-get install ocl-icd-libopencl1)"
    cp -L "$loader" "$CARRY/lib/libOpenCL.so.1"
    cp -L /usr/include/CL/*.h "$CARRY/include/CL/" ||
        die "--pack: no OpenCL headers here (apt-get install opencl-c-headers)"
    for h in png.h pngconf.h pnglibconf.h zlib.h zconf.h; do
        cp -L "/usr/include/$h" "$CARRY/include/" || die "--pack: no $h (apt-get install libpng-dev)"
    done
    for l in libpng16.so.16 libz.so.1; do
        p=$(cached_library $l)
        [ -n "$p" ] || die "--pack: no $l here"
        cp -L "$p" "$CARRY/lib/$l"
    done
    shared=$ROOT/../shared/data/benchmark
    for m in $MODELS; do
        if [ -f "$shared/$m/Noisy.obj" ]; then
            mkdir -p "$CARRY/shared/data/benchmark/$m"
            cp "$shared/$m/Noisy.obj" "$CARRY/shared/data/benchmark/$m/"
        else
            echo "gpu-check: --pack: $shared/$m/Noisy.obj absent: not packed" >&2
        fi
    done
    {
        echo "Packed by scripts/gpu-check.sh --pack on $(date -u +%FT%TZ) from $(. /etc/os-release; echo "$PRETTY_NAME")"
        echo "libOpenCL.so.1: ocl-icd $(dpkg-query -W -f '${Version}' ocl-icd-libopencl1 2>/dev/null), from $loader"
    } >"$CARRY/PACKED.txt"
    echo "gpu-check: packed $(du -sb "$CARRY" | cut -f1) bytes into $CARRY:"
    (cd "$CARRY" && find . -type f | sort)
    exit 0
fi

# --- set-up -------------------------------------------------------------------------------------
[ -n "$OUT_DIR" ] || die "no output folder: set OUT or pass --out DIR"
mkdir -p "$OUT_DIR" || die "cannot make $OUT_DIR"
OUT_DIR=$(cd "$OUT_DIR" && pwd)
if [ -z "$BUILD" ]; then
    if [ $SKIP_BUILD = 1 ]; then BUILD=$ROOT/build; else BUILD=$ROOT/build-gpu-check; fi
fi
case $BUILD in /*) ;; *) BUILD=$ROOT/$BUILD ;; esac
TMP=$(mktemp -d "${TMPDIR:-/tmp}/gpu-check.XXXXXX") || die "mktemp failed"
trap 'rm -rf "$TMP"' EXIT
LOG=$OUT_DIR/gpu-check.log
: >"$LOG"
# the only files written under OUT_DIR (the device tool brings back at most 8)
for f in gpu-check.json devices.txt bench-200k.json bench-1M.json bench-16M.json bench-bunny.json \
    best-bunny.json; do rm -f "$OUT_DIR/$f"; done

START=$(date +%s.%N)
DEADLINE=$(awk -v s="$START" -v b="$BUDGET" 'BEGIN { printf "%.0f", s + b }')
say() { echo "[gpu-check $(elapsed)s] $*" | tee -a "$LOG" >&2; }
elapsed() { awk -v s="$START" -v n="$(date +%s.%N)" 'BEGIN { printf "%.1f", n - s }'; }

# JSON string of $1
json_str() {
    printf '%s' "$1" | awk 'BEGIN { ORS = ""; print "\"" }
        { gsub(/\\/, "\\\\"); gsub(/"/, "\\\""); gsub(/\t/, "\\t"); gsub(/\r/, "");
          gsub(/[\001-\037]/, "?"); if (NR > 1) print "\\n"; print }
        END { print "\"" }'
}

STEPS_JSON=""
FAILED=""
# run_step NAME CAP STDOUT_FILE CMD...: runs CMD with at most min(CAP, time left) seconds, its
# stdout into STDOUT_FILE (or the log when "-"), stderr into the log; records time and outcome.
run_step() {
    local name=$1 cap=$2 stdout=$3 left rc t0 t1 secs status
    shift 3
    left=$(awk -v d="$DEADLINE" -v n="$(date +%s)" 'BEGIN { printf "%d", d - n }')
    [ "$left" -lt "$cap" ] && cap=$left
    if [ "$cap" -lt 5 ]; then
        say "$name: NOT RUN: the ${BUDGET}s budget is spent"
        STEPS_JSON+="${STEPS_JSON:+,}{\"step\":$(json_str "$name"),\"status\":\"not run (budget spent)\",\"seconds\":0}"
        FAILED+=" $name"
        return 1
    fi
    say "$name: $* (at most ${cap}s)"
    echo "----- $name: $*" >>"$LOG"
    t0=$(date +%s.%N)
    if [ "$stdout" = - ]; then
        timeout -k 10 "$cap" "$@" >>"$LOG" 2>&1
    else
        timeout -k 10 "$cap" "$@" >"$stdout" 2>>"$LOG"
    fi
    rc=$?
    t1=$(date +%s.%N)
    secs=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.1f", b - a }')
    if [ $rc = 0 ]; then
        status=ok
    elif [ $rc = 124 ] || [ $rc = 137 ]; then
        status="timed out after ${cap}s"
    else
        status="failed (exit $rc)"
    fi
    [ $rc = 0 ] || FAILED+=" $name"
    say "$name: $status in ${secs}s"
    STEPS_JSON+="${STEPS_JSON:+,}{\"step\":$(json_str "$name"),\"status\":$(json_str "$status"),\"seconds\":$secs}"
    return $rc
}

# --- the machine --------------------------------------------------------------------------------
MACHINE="$(uname -srm); $(nproc) cores; $(awk '/MemTotal/ { printf "%.0f GiB", $2 / 1048576 }' /proc/meminfo)"
MACHINE+="; $(. /etc/os-release 2>/dev/null && echo "$PRETTY_NAME")"
CPU=$(awk -F': ' '/model name/ { print $2; exit }' /proc/cpuinfo)
GPU=""
if command -v nvidia-smi >/dev/null 2>&1; then
    GPU=$(nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader 2>/dev/null | head -n 4 | tr '\n' ';')
fi
COMMIT=$(git -C "$ROOT" rev-parse --short HEAD 2>/dev/null || echo unknown)
say "machine: $MACHINE; CPU: $CPU; GPU: ${GPU:-none seen by nvidia-smi}; tree at $COMMIT"

# --- the vendor library and a private OCL_ICD_VENDORS -------------------------------------------
# Folders where drivers put their libraries: the linker's cache's, LD_LIBRARY_PATH's, the usual ones.
library_dirs() {
    { ldconfig -p 2>/dev/null | awk '/=>/ { sub(/\/[^\/]*$/, "", $NF); print $NF }'
        printf '%s\n' ${LD_LIBRARY_PATH:+${LD_LIBRARY_PATH//:/ }} /usr/local/nvidia/lib64 /usr/local/nvidia/lib \
            /usr/lib/x86_64-linux-gnu /usr/lib64 /usr/lib /lib/x86_64-linux-gnu /lib64 \
            /usr/lib/x86_64-linux-gnu/nvidia/current /usr/lib/nvidia /usr/lib64/nvidia \
            /run/nvidia/driver/usr/lib/x86_64-linux-gnu /run/nvidia/driver/usr/lib64
    } | awk 'NF && !seen[$0]++'
}

# The vendor's ICD library: the .icd file's name when it resolves, else the first NAME or NAME.*
# in the folders above. $1: the .icd file; $2: the library's soname.
find_vendor() {
    local icd=$1 name=$2 entry d f
    if [ -f "$icd" ]; then
        entry=$(head -n 1 "$icd" | tr -d '\r')
        case $entry in
        /*) [ -f "$entry" ] && { echo "$entry"; return 0; } ;;
        ?*) name=$entry ;;
        esac
    fi
    for d in $(library_dirs); do
        for f in "$d/$name" "$d/$name".*; do
            [ -f "$f" ] && { echo "$f"; return 0; }
        done
    done
    return 1
}

VENDOR=""
case $KIND in
nvidia)
    VENDOR=$(find_vendor /etc/OpenCL/vendors/nvidia.icd libnvidia-opencl.so.1) ||
        die "no NVIDIA OpenCL library (libnvidia-opencl.so.1) in: $(library_dirs | tr '\n' ' ')"
    DEVICE=gpu TYPE=gpu EXPECT=NVIDIA ;;
pocl)
    VENDOR=$(find_vendor /etc/OpenCL/vendors/pocl.icd libpocl.so.2) ||
        die "no PoCL library (libpocl.so.2; apt-get install pocl-opencl-icd)"
    DEVICE=cpu TYPE=cpu EXPECT="Portable Computing Language" ;;
*) DEVICE=$KIND TYPE="" EXPECT="" ;;
esac
if [ -n "$VENDOR" ]; then
    mkdir -p "$TMP/vendors"
    echo "$VENDOR" >"$TMP/vendors/$KIND.icd"
    export OCL_ICD_VENDORS=$TMP/vendors OPENCL_VENDOR_PATH=$TMP/vendors
    # the vendor's own dependencies (libcuda.so.1 beside libnvidia-opencl) from the same folder
    LD_LIBRARY_PATH=${VENDOR%/*}${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
    export LD_LIBRARY_PATH
    say "vendor library: $VENDOR (private OCL_ICD_VENDORS=$TMP/vendors)"
fi
# the tests alone force the GPU kernel variant (below); the bench and the command run the variant
# the device picks (the group variant on a GPU, the block variant on PoCL's CPU device)
export RSMOOTH_DEVICE=$DEVICE RSMOOTH_REQUIRE_OPENCL=1
export POCL_CACHE_DIR=$TMP/pocl-cache RSMOOTH_CACHE_DIR=$TMP/rsmooth-cache
mkdir -p "$RSMOOTH_CACHE_DIR" && chmod 700 "$RSMOOTH_CACHE_DIR"

# --- build, or the carried build ------------------------------------------------------------------
TARGETS="rsmooth_cli rsmooth_bench rsmooth_demo_shape test_cl_vs_reference test_cl_beyond test_cl_stage"
BUILT_HERE=0
if [ $SKIP_BUILD = 0 ]; then
    SHARED_ARG=()
    if [ ! -d "$ROOT/../shared/data/benchmark" ] && [ -d "$CARRY/shared/data/benchmark" ]; then
        SHARED_ARG=("-DRSMOOTH_SHARED_DIR=$CARRY/shared")
    fi
    CONFIGURE=(cmake -S "$ROOT" -B "$BUILD" -DCMAKE_BUILD_TYPE=Release -DRSMOOTH_INSTALL=OFF
        "${SHARED_ARG[@]}")
    if ! run_step configure 120 - "${CONFIGURE[@]}"; then
        # a bare machine: no OpenCL headers or no libpng/zlib development files; .gpu-check has both
        [ -d "$CARRY/include" ] || die "configure failed and $CARRY (scripts/gpu-check.sh --pack) is absent; see $LOG"
        FAILED=""
        STEPS_JSON=${STEPS_JSON/\"step\":\"configure\"/\"step\":\"configure (system only)\"}
        run_step "configure (.gpu-check headers)" 120 - "${CONFIGURE[@]}" \
            -DOpenCL_INCLUDE_DIR="$CARRY/include" \
            -DPNG_PNG_INCLUDE_DIR="$CARRY/include" -DPNG_LIBRARY="$CARRY/lib/libpng16.so.16" \
            -DZLIB_INCLUDE_DIR="$CARRY/include" -DZLIB_LIBRARY="$CARRY/lib/libz.so.1"
    fi
    # shellcheck disable=SC2086 # TARGETS is a list
    [ -z "$FAILED" ] && run_step build 240 - cmake --build "$BUILD" -j "$JOBS" --target $TARGETS
    [ -z "$FAILED" ] && BUILT_HERE=1
fi
RSMOOTH=$BUILD/rsmooth BENCH=$BUILD/rsmooth-bench SHAPE=$BUILD/rsmooth-demo-shape
for p in "$RSMOOTH" "$BENCH" "$BUILD/tests/test_cl_vs_reference" "$BUILD/tests/test_cl_beyond" \
    "$BUILD/tests/test_cl_stage"; do
    [ -x "$p" ] || { FAILED+=" programs"; say "FAILED: $p is missing (build failed, or the carried build lacks it)"; }
done
if [ -n "$FAILED" ]; then
    say "FAILED:$FAILED; stopping (see $LOG)"
    printf '{"result":"failed","failed":%s,"steps":[%s]}\n' "$(json_str "${FAILED# }")" "$STEPS_JSON" >"$OUT_DIR/gpu-check.json"
    exit 1
fi
# a carried build's libpng and zlib, where this machine has none (after the system's own)
if ldd "$RSMOOTH" 2>/dev/null | grep -q 'not found' && [ -d "$CARRY/lib" ]; then
    export LD_LIBRARY_PATH=${LD_LIBRARY_PATH:+$LD_LIBRARY_PATH:}$CARRY/lib
    say "libraries the programs lack are taken from $CARRY/lib"
fi

# --- the ICD loader: the user's, the system's, CUDA's, or the carried copy ----------------------
lists_device() { # $1: output of --list-devices
    if [ -n "$TYPE" ]; then
        printf '%s\n' "$1" | grep -E "^[0-9]+:[0-9]+ +$TYPE " | grep -q "$EXPECT"
    else
        printf '%s\n' "$1" | grep -qE '^[0-9]+:[0-9]+ '
    fi
}
CANDIDATES=()
[ -n "${RSMOOTH_OPENCL_LIBRARY:-}" ] && CANDIDATES+=("$RSMOOTH_OPENCL_LIBRARY")
p=$(cached_library libOpenCL.so.1) && [ -n "$p" ] && CANDIDATES+=("$p")
for p in /usr/local/cuda*/lib64/libOpenCL.so.1 /usr/local/cuda*/targets/x86_64-linux/lib/libOpenCL.so.1 \
    "$CARRY/lib/libOpenCL.so.1"; do
    [ -f "$p" ] && CANDIDATES+=("$p")
done
LOADER=""
t0=$(date +%s.%N)
for p in "${CANDIDATES[@]}"; do
    listing=$(RSMOOTH_OPENCL_LIBRARY=$p timeout 60 "$RSMOOTH" --list-devices 2>&1)
    echo "----- loader $p: rsmooth --list-devices" >>"$LOG"
    printf '%s\n' "$listing" >>"$LOG"
    if lists_device "$listing"; then
        LOADER=$(readlink -f "$p")
        break
    fi
done
secs=$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')
if [ -z "$LOADER" ]; then
    say "FAILED: no ICD loader lists a ${TYPE:-OpenCL} device${EXPECT:+ named $EXPECT} (tried: ${CANDIDATES[*]:-none}; carried one: run --pack and carry .gpu-check); see $LOG"
    printf '%s\n' "${listing:-}" >"$OUT_DIR/devices.txt"
    printf '{"result":"failed","failed":"list-devices","steps":[%s]}\n' "$STEPS_JSON" >"$OUT_DIR/gpu-check.json"
    exit 1
fi
export RSMOOTH_OPENCL_LIBRARY=$LOADER
printf '%s\n' "$listing" >"$OUT_DIR/devices.txt"
STEPS_JSON+="${STEPS_JSON:+,}{\"step\":\"list-devices\",\"status\":\"ok\",\"seconds\":$secs}"
say "list-devices: ok in ${secs}s with the loader $LOADER:"
printf '%s\n' "$listing" | tee -a "$LOG" >&2

# --- the tests, GPU kernel variant ----------------------------------------------------------------
# cl_stage: the best mode's normal-update stage on the device against the host's, both kernel
# variants itself, at its smaller sizes (RSMOOTH_TEST_SMALL: Fandisk0.3 of the meshes, drift to
# 100 cycles) to fit the budget
for t in cl_vs_reference cl_beyond cl_stage; do
    small=0
    [ "$t" = cl_stage ] && small=1
    if [ $BUILT_HERE = 1 ]; then
        # the ctest names; -V prints each test's own lines (its device, each case's deviation)
        run_step "test $t" 240 - env RSMOOTH_KERNEL_VARIANT=gpu RSMOOTH_TEST_SMALL=$small bash -c \
            'cd "$1" && ctest -R "^$2\$" --output-on-failure -V' ctest "$BUILD" "$t"
    else
        # a carried build's CTestTestfile names the folders of the machine it was built on
        run_step "test $t" 240 - env RSMOOTH_KERNEL_VARIANT=gpu RSMOOTH_TEST_SMALL=$small \
            "$BUILD/tests/test_$t"
    fi
done
DEVICE_NAME=$(grep -m 1 -E '^([0-9]+: )?device: ' "$LOG" | sed -E 's/^([0-9]+: )?device: //; s/ \(program build.*//')
grep -q 'benchmark meshes: .* absent, skipped' "$LOG" &&
    say "note: the tests found no benchmark meshes (their cases on them were skipped)"

# --- the bench ------------------------------------------------------------------------------------
if [ -z "$BUNNY" ]; then
    for p in "$ROOT/../shared/data/benchmark/Bunny0.2/Noisy.obj" \
        "$CARRY/shared/data/benchmark/Bunny0.2/Noisy.obj"; do
        [ -f "$p" ] && { BUNNY=$p; break; }
    done
fi
BUNNY_KIND="Bunny0.2 ($BUNNY)"
if [ -z "$BUNNY" ]; then
    BUNNY=$TMP/bunny-sized.obj
    BUNNY_KIND="NOT Bunny0.2: a generated cylinder of Bunny0.2's 69451 triangles, noise 0.2"
    run_step "generate bunny-sized mesh" 60 - "$SHAPE" make "$BUNNY" "$TMP/bunny-truth.obj" \
        --triangles 69451 --noise 0.2
fi
say "Bunny case: $BUNNY_KIND"

run_step "bench 200k" 90 "$OUT_DIR/bench-200k.json" "$BENCH" filter --triangles 200000 \
    --sigma-f 4 --sigma-g 1 --repeat 9
run_step "bench 1M" 90 "$OUT_DIR/bench-1M.json" "$BENCH" filter --triangles 1000000 --repeat 5 \
    --no-pairs
run_step "bench bunny" 90 "$OUT_DIR/bench-bunny.json" "$BENCH" filter "$BUNNY" --repeat 9
# --best against the paper filter, its normal-update stage on the host and on the device (double
# and float32), part by part, with the bytes moved and the device's deviation from the host's
run_step "best bunny" 120 "$OUT_DIR/best-bunny.json" "$BENCH" best "$BUNNY" --repeat 3 \
    --device "$DEVICE"
# last: the largest, capped, so that a slow device still leaves the figures above
run_step "bench 16M" "$CAP_16M" "$OUT_DIR/bench-16M.json" "$BENCH" filter --triangles 16000000 \
    --repeat 3 --no-pairs

# --- the summary ----------------------------------------------------------------------------------
embed() { # the JSON file $1, or null when it is missing or empty
    if [ -s "$1" ]; then cat "$1"; else echo null; fi
}
for f in bench-200k bench-1M bench-16M bench-bunny best-bunny; do # a step cut short: no JSON
    [ -s "$OUT_DIR/$f.json" ] || rm -f "$OUT_DIR/$f.json"
done
TOTAL=$(elapsed)
RESULT=ok
[ -n "$FAILED" ] && RESULT=failed
{
    printf '{\n"result": "%s",\n"failed": %s,\n' "$RESULT" "$(json_str "${FAILED# }")"
    printf '"total_seconds": %s,\n"budget_seconds": %s,\n' "$TOTAL" "$BUDGET"
    printf '"device_kind": %s,\n"device": %s,\n' "$(json_str "$KIND")" "$(json_str "${DEVICE_NAME:-}")"
    printf '"machine": %s,\n"cpu": %s,\n"gpu": %s,\n' "$(json_str "$MACHINE")" "$(json_str "$CPU")" "$(json_str "$GPU")"
    printf '"commit": %s,\n"loader": %s,\n"vendor_library": %s,\n' "$(json_str "$COMMIT")" \
        "$(json_str "$LOADER")" "$(json_str "$VENDOR")"
    printf '"build": %s,\n"bunny": %s,\n' "$(json_str "$([ $BUILT_HERE = 1 ] && echo "built here in $BUILD" || echo "carried: $BUILD")")" \
        "$(json_str "$BUNNY_KIND")"
    printf '"steps": [%s],\n' "$STEPS_JSON"
    printf '"bench_200k": %s,\n' "$(embed "$OUT_DIR/bench-200k.json")"
    printf '"bench_1M": %s,\n' "$(embed "$OUT_DIR/bench-1M.json")"
    printf '"bench_16M": %s,\n' "$(embed "$OUT_DIR/bench-16M.json")"
    printf '"bench_bunny": %s,\n' "$(embed "$OUT_DIR/bench-bunny.json")"
    printf '"best_bunny": %s\n}\n' "$(embed "$OUT_DIR/best-bunny.json")"
} >"$OUT_DIR/gpu-check.json"

say "steps:"
printf '%s\n' "$STEPS_JSON" | tr '{' '\n' | sed -n 's/.*"step":"\([^"]*\)","status":"\([^"]*\)","seconds":\([0-9.]*\).*/  \3 s  \1: \2/p' |
    tee -a "$LOG" >&2
if [ -n "$FAILED" ]; then
    say "FAILED:$FAILED (total ${TOTAL}s; the log: $LOG)"
    exit 1
fi
say "all steps passed in ${TOTAL}s on ${DEVICE_NAME:-?}; JSON in $OUT_DIR"
