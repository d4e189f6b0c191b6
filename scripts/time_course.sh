#!/usr/bin/env bash
# Times the course's seven grading commands at 800×800 (the commands of tests/data/mit6837/README.md),
# each a separate `goldray mit6837` process, as a TA would run them. Prints the wall time of each
# command and of all seven, and the processor time (user + system) the seven used, for every binary
# given, alternating the binaries round by round so that the shared machine's load falls on each
# alike. On a busy machine the wall times follow the load; the processor time much less so.
#
#   scripts/time_course.sh [-n ROUNDS] [-o OUT_DIR] [-c COURSE_BINARY] GOLDRAY_BINARY...
#
# Run from the project root (the scenes are read from cases/mit6837/). OUT_DIR defaults to a fresh
# temporary folder; the pictures left there can be compared between binaries. With -c, the course's
# own renderer (`a2`) runs the same commands in each round too (from cases/mit6837/, where its scene
# files find their meshes and cube map), for a ratio measured under the same load.
set -euo pipefail
rounds=5
out=""
course=""
usage="usage: $0 [-n ROUNDS] [-o OUT_DIR] [-c COURSE_BINARY] GOLDRAY_BINARY..."
while getopts "n:o:c:" flag; do
    case $flag in
        n) rounds=$OPTARG ;;
        o) out=$OPTARG ;;
        c) course=$(realpath "$OPTARG") ;;
        *) echo "$usage" >&2; exit 2 ;;
    esac
done
shift $((OPTIND - 1))
[ $# -ge 1 ] || { echo "$usage" >&2; exit 2; }
[ -n "$out" ] || out=$(mktemp -d)
out=$(realpath "$out")
binaries=("$@")
[ -z "$course" ] || binaries+=("$course")
scenes=cases/mit6837
# Scene number, scene file, depth range, further flags.
commands=(
    "01 scene01_plane 8 18"
    "02 scene02_cube 8 18"
    "03 scene03_sphere 8 18"
    "04 scene04_axes 8 18"
    "05 scene05_bunny_200 0.8 1.0"
    "06 scene06_bunny_1k 8 18 -bounces 4"
    "07 scene07_arch 8 18 -bounces 4 -shadows"
)
# User plus system seconds of all finished child processes so far (the second line of bash's
# `times`, which must run in this shell, not in a command substitution's subshell).
children_cpu() {
    times >"$out/.times"
    tail -1 "$out/.times" | awk '{ gsub(/[ms]/, " "); print $1 * 60 + $2 + $3 * 60 + $4 }'
}
for round in $(seq "$rounds"); do
    for binary in "${binaries[@]}"; do
        dir="$out/$(basename "$binary")"
        mkdir -p "$dir"
        children_cpu >"$out/.cpu"
        cpu=$(cat "$out/.cpu")
        # The harness reads bash's own clock (no process started to read it) and works each
        # command's time out after the round: a `date` and a `bc` a command would add their own
        # process starts to every round (about 5 ms a command, a tenth of goldray's round and
        # nothing of the course binary's).
        names=()
        stamps=("${EPOCHREALTIME/,/.}")
        for command in "${commands[@]}"; do
            read -r n scene min max flags <<<"$command"
            names+=("a$n")
            # shellcheck disable=SC2086 # the further flags are separate words
            if [ "$binary" = "$course" ]; then
                (cd "$scenes" && "$binary" -size 800 800 -input "$scene.txt" $flags -output "$dir/a$n.png" \
                    -normals "$dir/a${n}n.png" -depth "$min" "$max" "$dir/a${n}d.png" >/dev/null)
            else
                "$binary" mit6837 -size 800 800 -input "$scenes/$scene.txt" $flags -output "$dir/a$n.png" \
                    -normals "$dir/a${n}n.png" -depth "$min" "$max" "$dir/a${n}d.png" --quiet
            fi
            stamps+=("${EPOCHREALTIME/,/.}")
        done
        line=$(awk -v names="${names[*]}" -v stamps="${stamps[*]}" 'BEGIN {
            n = split(names, name, " "); split(stamps, t, " ")
            for (k = 1; k <= n; k++) printf " %s %.3f", name[k], t[k + 1] - t[k]
        }')
        total=$(awk -v a="${stamps[0]}" -v b="${stamps[${#stamps[@]} - 1]}" 'BEGIN { printf "%.3f", b - a }')
        children_cpu >"$out/.cpu"
        used=$(echo "$(cat "$out/.cpu") - $cpu" | bc | xargs printf '%.3f')
        echo "round $round $(basename "$binary"): total $total s, processor $used s |$line"
    done
done
