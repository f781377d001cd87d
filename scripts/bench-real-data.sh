#!/usr/bin/env bash
# The priorlets engine on real laser logs (issue 4, real data): runs
#   priormap scan --prior PRIOR --log LOG --all -o OUT.jsonl
# on every laser log of ../shared/data (laser-corrected/*.log.gz and laser-raw-mbicp/*.log.gz;
# not the sonar data) or on the logs given as arguments, and prints per log: scans, wall time,
# wall ms per scan (the CLI solves scans in parallel: divide by the threads for CPU time), the
# engine's own mean ms per scan, the fraction of valid readings in the model, NaN count (in-model
# beams whose rho or alpha is null/NaN), infeasible scans and failed scans (error records).
#
# usage: scripts/bench-real-data.sh [-b PRIORMAP] [-p PRIOR] [-t THREADS] [-k] [LOG...]
#   -b  the priormap binary (default: $PRIORMAP, else build/release/bin/priormap)
#   -p  the prior (default polygonal)
#   -t  run the CLI on the first THREADS cores only (taskset; default: all cores)
#   -k  keep the JSON Lines outputs (printed at the end)
# Needs python3.
set -euo pipefail
cd "$(dirname "$0")/.."

binary="${PRIORMAP:-build/release/bin/priormap}"
prior=polygonal
threads=""
keep=0
while getopts "b:p:t:kh" opt; do
  case "$opt" in
    b) binary="$OPTARG" ;;
    p) prior="$OPTARG" ;;
    t) threads="$OPTARG" ;;
    k) keep=1 ;;
    *) sed -n '2,16p' "$0" | sed 's/^# \{0,1\}//'; exit 2 ;;
  esac
done
shift $((OPTIND - 1))

if [[ ! -x "$binary" ]]; then
  echo "bench-real-data: no priormap binary at '$binary' (build it, or pass -b / set PRIORMAP)" >&2
  exit 1
fi
command -v python3 >/dev/null || { echo "bench-real-data: python3 is needed" >&2; exit 1; }

data=../shared/data
logs=("$@")
if [[ ${#logs[@]} -eq 0 ]]; then
  if [[ ! -d "$data" ]]; then
    echo "bench-real-data: $data not found; pass the logs as arguments" >&2
    exit 1
  fi
  logs=("$data"/laser-corrected/*.log.gz "$data"/laser-raw-mbicp/*.log.gz)
fi

runner=()
if [[ -n "$threads" ]]; then
  # Pin the CLI (and so its TBB pool) to the first THREADS cores.
  runner=(taskset -c "0-$((threads - 1))")
fi

work="$(mktemp -d "${TMPDIR:-/tmp}/bench-real-data.XXXXXX")"
if [[ $keep -eq 0 ]]; then trap 'rm -rf "$work"' EXIT; fi

summarise() {  # summarise LOG_JSON MAP_JSONL NAME WALL_SECONDS
  python3 - "$@" <<'PY'
import json, math, sys

log_path, map_path, name, wall = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])

# Valid readings per scan, from the log converted to priormap JSON (docs/formats.md: finite,
# > 0, >= min_range, < max_range, unless a status array says otherwise).
valid = []
with open(log_path) as f:
    doc = json.load(f)
for record in doc["records"]:
    if record.get("type") != "scan":
        continue
    if "status" in record:
        valid.append(sum(1 for s in record["status"] if s == "valid"))
        continue
    lo = record.get("min_range", 0.0)
    hi = record.get("max_range", "inf")
    hi = math.inf if hi == "inf" else float(hi)
    n = 0
    for r in record["ranges"]:
        if isinstance(r, (int, float)) and math.isfinite(r) and r > 0 and r >= lo and r < hi:
            n += 1
    valid.append(n)

def nan(v):
    return v is None or (isinstance(v, float) and math.isnan(v)) or v in ("nan", "inf", "-inf")

scans = failures = infeasible = nan_count = inmodel = valid_total = 0
engine_seconds = 0.0
with open(map_path) as f:
    for line in f:
        if not line.strip():
            continue
        m = json.loads(line)
        scans += 1
        if "error" in m:
            failures += 1
            continue
        k = m["scan_index"]
        beams = m["inmodel_beams"]
        inmodel += len(beams)
        valid_total += valid[k] if k < len(valid) else 0
        nan_count += sum(1 for i in beams if nan(m["rho"][i]) or nan(m["alpha"][i]))
        infeasible += 0 if m["feasible"] else 1
        engine_seconds += m["stats"]["seconds"]
solved = scans - failures
print(f"{name:<40} {scans:>6} {wall:>9.1f} {1e3 * wall / max(scans, 1):>9.1f} "
      f"{1e3 * engine_seconds / max(solved, 1):>10.1f} "
      f"{inmodel / valid_total if valid_total else float('nan'):>8.3f} {nan_count:>6} "
      f"{infeasible:>6} {failures:>6}")
PY
}

printf "%-40s %6s %9s %9s %10s %8s %6s %6s %6s\n" log scans wall-s wall-ms engine-ms inmodel \
  NaN infeas failed
status=0
for log in "${logs[@]}"; do
  name="$(basename "$log")"
  base="$work/${name%%.*}"
  if ! "$binary" convert "$log" -o "$base.log.json" >"$base.convert.txt" 2>&1; then
    printf "%-40s conversion failed: %s\n" "$name" "$(tail -1 "$base.convert.txt")"
    status=1
    continue
  fi
  start=$(date +%s.%N)
  rm -f "$base.jsonl"
  scan_status=0
  "${runner[@]}" "$binary" scan --prior "$prior" --log "$log" --all -o "$base.jsonl" \
    >"$base.scan.txt" 2>&1 || scan_status=$?
  # scan --all exits 1 when some scans failed, after writing every scan's record: the
  # summary's failed column counts them.
  if [[ ! -f "$base.jsonl" ]]; then
    printf "%-40s priormap scan failed: %s\n" "$name" "$(tail -1 "$base.scan.txt")"
    status=1
    continue
  fi
  if [[ $scan_status -ne 0 ]]; then status=1; fi
  end=$(date +%s.%N)
  summarise "$base.log.json" "$base.jsonl" "$name" "$(python3 -c "print($end - $start)")"
done
if [[ $keep -eq 1 ]]; then echo "outputs kept in $work"; fi
exit $status
