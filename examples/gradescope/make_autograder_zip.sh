#!/usr/bin/env bash
# Makes the zip a TA uploads to Gradescope ("Configure Autograder", "Zip file upload"):
# setup.sh, run_autograder, goldray's source (with the course's scenes), and which rubric of it
# grades.
#
#   examples/gradescope/make_autograder_zip.sh rubrics/mit6837.toml autograder.zip
#
# The rubric must be inside this repository (commit your course's rubric under rubrics/, its
# scenes under cases/), because its render paths are relative to it and the repository is what
# the zip ships.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
rubric=$(realpath "${1:?give the rubric: make_autograder_zip.sh RUBRIC.toml OUT.zip}")
out=$(realpath -m "${2:?give the zip to write: make_autograder_zip.sh RUBRIC.toml OUT.zip}")
case "$rubric" in
    "$repo"/*) ;;
    *) echo "error: $rubric is not inside $repo: commit it there first" >&2; exit 2 ;;
esac

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cp "$here/setup.sh" "$here/run_autograder" "$work/"
git -C "$repo" archive --format=tar.gz -o "$work/goldray.tar.gz" HEAD
realpath --relative-to="$repo" "$rubric" > "$work/rubric-path"
rm -f "$out"
(cd "$work" && python3 -m zipfile -c "$out" setup.sh run_autograder goldray.tar.gz rubric-path)
echo "wrote $out: upload it as the autograder (Ubuntu base image)"
