#!/usr/bin/env bash
# Times the render phase of every shipped case (cases/*.toml) for each binary given, alternating
# the binaries case by case and round by round so that the machine's load falls on each alike, and
# prints each case's fastest render time per binary and its ratio to the first binary. The render
# time is `--stats-json`'s `seconds.render` (the scene build and the writing excluded), so process
# start and disk do not blur it.
#
#   scripts/time_cases.sh [-n ROUNDS] [-t THREADS] BASELINE_BINARY OTHER_BINARY...
#
# Run from the project root. A ratio above 1 means the other binary is slower than the baseline.
set -euo pipefail
rounds=5
threads=1
usage="usage: $0 [-n ROUNDS] [-t THREADS] BASELINE_BINARY OTHER_BINARY..."
while getopts "n:t:" flag; do
    case $flag in
        n) rounds=$OPTARG ;;
        t) threads=$OPTARG ;;
        *) echo "$usage" >&2; exit 2 ;;
    esac
done
shift $((OPTIND - 1))
[ $# -ge 2 ] || { echo "$usage" >&2; exit 2; }
binaries=("$@")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

for case in cases/*.toml; do
    name=$(basename "$case" .toml)
    for round in $(seq "$rounds"); do
        for index in "${!binaries[@]}"; do
            "${binaries[$index]}" render "$case" --out "$work/out" --threads "$threads" --quiet \
                --stats-json "$work/stats.json"
            python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["seconds"]["render"])' \
                "$work/stats.json" >> "$work/$name.$index"
        done
    done
done

python3 - "$work" "${#binaries[@]}" "${binaries[@]}" <<'EOF'
import pathlib, sys
work, count, names = pathlib.Path(sys.argv[1]), int(sys.argv[2]), sys.argv[3:]
cases = sorted({p.stem for p in work.glob("*.0")})
print(f"{'case':28}" + "".join(f"{pathlib.Path(n).name[:14]:>16}" for n in names) + "   ratios to the first")
worst = [0.0] * count
for case in cases:
    best = [min(float(t) for t in (work / f"{case}.{i}").read_text().split()) for i in range(count)]
    ratios = [b / best[0] if best[0] > 0 else 1.0 for b in best]
    worst = [max(w, r) for w, r in zip(worst, ratios)]
    print(f"{case:28}" + "".join(f"{b * 1000:14.2f}ms" for b in best) + "   " + " ".join(f"{r:.3f}" for r in ratios[1:]))
print(f"{'slowest ratio':28}" + " " * 16 * count + "   " + " ".join(f"{w:.3f}" for w in worst[1:]))
EOF
