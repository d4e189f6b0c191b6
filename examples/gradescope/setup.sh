#!/usr/bin/env bash
# Gradescope runs this once, as root, when it builds the autograder's image (Ubuntu): it builds
# goldray from the source shipped in the zip, installs it, and renders the rubric's golden images
# and the mistakes' pictures into a cache, so that grading a submission renders nothing.
set -euo pipefail
source_dir=/autograder/source

apt-get update
DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends \
    curl ca-certificates build-essential g++
if ! command -v cargo >/dev/null 2>&1; then
    curl --proto '=https' --tlsv1.2 -sSf https://sh.rustup.rs | sh -s -- -y --profile minimal
fi
# shellcheck disable=SC1091
source "$HOME/.cargo/env"

mkdir -p "$source_dir/goldray"
tar -xzf "$source_dir/goldray.tar.gz" -C "$source_dir/goldray"
cargo install --locked --path "$source_dir/goldray" --root /usr/local
# The golden images and the mistakes' pictures, rendered now rather than per submission. The
# rubric is the one make_autograder_zip.sh named, read where it is (its paths are relative to it).
goldray grade --prepare --rubric "$source_dir/goldray/$(cat "$source_dir/rubric-path")" \
    --cache "$source_dir/cache"
