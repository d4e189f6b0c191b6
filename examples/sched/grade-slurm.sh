#!/usr/bin/env bash
# Grades a class on a Slurm cluster with goldray: a job array of SHARDS tasks, each grading one
# slice of the class, then a merge job that runs once every task has succeeded.
#
#   examples/sched/grade-slurm.sh RUBRIC SUBMISSIONS OUT [SHARDS]
#
# Run it on the login node, with the paths on a file system the compute nodes share. It fills the
# golden cache once (goldray grade --prepare, in OUT/cache unless GOLDRAY_CACHE says otherwise),
# then submits itself as the array: task K grades slice K/SHARDS into OUT/shards/K, reading the
# cache only. A task that fails can be resubmitted alone (sbatch --array=K); a task that is
# requeued resumes, keeping the students it had finished. The merge writes OUT/grades.csv,
# OUT/grades.json and OUT/index.html. GOLDRAY names the goldray binary (default: goldray on PATH).
#SBATCH --job-name=goldray-grade
#SBATCH --cpus-per-task=4
#SBATCH --mem=2G
#SBATCH --time=02:00:00
#SBATCH --requeue
set -euo pipefail

if [[ $# -lt 3 ]]; then
  echo "usage: $0 RUBRIC SUBMISSIONS OUT [SHARDS]" >&2
  exit 2
fi
rubric=$(realpath "$1")
submissions=$(realpath "$2")
mkdir -p "$3"
out=$(realpath "$3")
shards=${4:-8}
goldray=${GOLDRAY:-goldray}
cache=${GOLDRAY_CACHE:-$out/cache}

if [[ -n "${SLURM_ARRAY_TASK_ID:-}" ]]; then
  # One task of the array: slice K of the class.
  k=$SLURM_ARRAY_TASK_ID
  exec "$goldray" grade --rubric "$rubric" "$submissions" --cache "$cache" \
    --shard "$k/$shards" --out "$out/shards/$k" --threads "${SLURM_CPUS_PER_TASK:-1}"
fi

"$goldray" grade --prepare --rubric "$rubric" --cache "$cache"
script=$(realpath "$0")
array=$(sbatch --parsable --array="1-$shards" --output="$out/shards/slurm-%a.log" \
  "$script" "$rubric" "$submissions" "$out" "$shards")
array=${array%%;*}
shard_dirs=()
for k in $(seq 1 "$shards"); do
  shard_dirs+=("$out/shards/$k")
done
merge=$(printf '%q ' "$goldray" grade --merge "$out" "${shard_dirs[@]}")
sbatch --parsable --job-name=goldray-merge --dependency="afterok:$array" \
  --output="$out/merge.log" --wrap "$merge"
echo "submitted: grading array $array ($shards tasks), then the merge into $out"
