#!/bin/sh
# Regenerates the pictures in this folder with the course's own binary: the course's scenes,
# each edited (or rendered with other flags) the way one classic mistake changes what a program
# draws. tests/diagnose.rs grades them as independent student submissions.
#
#   tests/data/mit6837/faulty/make.sh /path/to/a2
#
# Needs the course's reference binary (`a2`, see ../README.md), python3 for the scene edits, and
# is run from anywhere; it writes NAME/FILE.png beside itself, where NAME is the mistake.
set -eu
A2=$(realpath "$1")
HERE=$(cd "$(dirname "$0")" && pwd)
DATA=$(cd "$HERE/../../../../cases/mit6837" && pwd)
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
cp -r "$DATA" "$WORK/data"
cd "$WORK"

# edit SCENE 'python expression on text t' OUT: a copy of the scene with the edit applied.
edit() {
    python3 -c "import sys; t = open(sys.argv[1]).read(); open(sys.argv[2], 'w').write($2)" "data/$1" "data/$3"
}

# render NAME SCENE FLAGS...: colour, normals and depth at 200x200 into NAME/ (depth 8..18 as the
# course's commands, 0.8..1 for scene 05), keeping only the files listed in KEEP.
render() {
    name=$1; scene=$2; number=$3; shift 3
    range="8 18"; [ "$number" = 05 ] && range="0.8 1.0"
    mkdir -p "$HERE/$name"
    "$A2" -size 200 200 -input "data/$scene" "$@" -output "a$number.png" -normals "a${number}n.png" \
        -depth $range "a${number}d.png" > /dev/null
    for file in $KEEP; do mv "$file" "$HERE/$name/"; done
    rm -f a*.png
}

edit scene01_plane.txt "t.replace('ambientLight 0.1 0.1 0.1', 'ambientLight 0 0 0')" s01_no_ambient.txt
KEEP=a01.png render no-ambient s01_no_ambient.txt 01
edit scene05_bunny_200.txt "t.replace('ambientLight 0.1 0.1 0.1', 'ambientLight 0 0 0')" s05_no_ambient.txt
KEEP=a05.png render no-ambient s05_no_ambient.txt 05

edit scene01_plane.txt "t.replace('color 0.9 0.9 0.9', 'color 1 1 1')" s01_white.txt
KEEP=a01.png render light-color-ignored s01_white.txt 01

edit scene01_plane.txt "t.replace('angle 30', 'angle 60')" s01_fov.txt
KEEP="a01.png a01n.png a01d.png" render fov-half-angle s01_fov.txt 01

edit scene02_cube.txt "t.replace('direction -0.5 -0.3 -1', 'direction 0.5 0.3 1')" s02_flipped.txt
KEEP=a02.png render directional-flipped s02_flipped.txt 02

# up minus its component along the view direction, normalised.
edit scene02_cube.txt "t.replace('up 0 1 0', 'up -0.182574186 0.912870929 -0.365148372')" s02_up.txt
KEEP="a02.png a02n.png a02d.png" render up-orthonormalized s02_up.txt 02

edit scene03_sphere.txt "t.replace('ZRotate  45 \n        Scale  1 0.2 1', 'Scale  1 0.2 1\n        ZRotate  45')" s03_order.txt
KEEP="a03.png a03n.png a03d.png" render transform-order-reversed s03_order.txt 03

KEEP=a06.png render no-reflections scene06_bunny_1k.txt 06 -bounces 0
KEEP=a06.png render wrong-bounces scene06_bunny_1k.txt 06 -bounces 1

edit scene06_bunny_1k.txt "t.replace('cubeMap tex/church', '')" s06_no_cubemap.txt
KEEP=a06.png render cubemap-ignored s06_no_cubemap.txt 06 -bounces 4

KEEP=a07.png render no-shadows scene07_arch.txt 07 -bounces 4
