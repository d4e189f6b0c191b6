#!/usr/bin/env bash
# Fills fuzz/corpus/<target>/ with seed inputs: the project's own cases, the course's scenes and
# meshes (cases/mit6837/), one of its reference images, a fresh render, and random valid course
# scenes from the differential test's generator (examples/course_diff).
set -euo pipefail
cd "$(dirname "$0")"
course=../cases/mit6837
mkdir -p corpus/case_toml corpus/assignment_scene corpus/obj corpus/png_decode
cp ../cases/*.toml corpus/case_toml/
cp "$course"/scene0*.txt corpus/assignment_scene/
cp "$course"/models/cube*.obj "$course"/models/c1.obj "$course"/models/bunny_200.obj corpus/obj/
cp ../tests/data/mit6837/a02.png corpus/png_decode/
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\n' > corpus/obj/triangle.obj
printf 'PerspectiveCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 angle 30 }\nMaterials { numMaterials 1 Material { } }\nGroup { numObjects 1 MaterialIndex 0 Sphere { center 0 0 0 radius 1 } }\n' > corpus/assignment_scene/minimal.txt
# Random valid scenes of the differential test: every block, field orders, number forms, nesting.
cargo run --quiet --release --manifest-path ../Cargo.toml --example course_diff -- \
    --write-scenes corpus/assignment_scene --seeds 1-60
cargo run --quiet --release --manifest-path ../Cargo.toml -- render ../cases/directional_light.toml --out corpus/png_decode/render --quiet
mv corpus/png_decode/render/directional_light.png corpus/png_decode/ && rm -rf corpus/png_decode/render
