#!/bin/sh
# Compile time of a crate instantiating the generated models planar 1..16 and spatial 1..8
# (docs/bench.md, "Compile time"): clean and incremental (`touch`) builds of that crate
# alone, dependencies built first, in the dev and release profiles; then the same with
# every model `algorithm: dense`. Run from the repository root: `sh docs/compile-time.sh`.
set -eu
root=$(pwd)
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
mkdir "$dir/src"
cat > "$dir/Cargo.toml" <<TOML
[package]
name = "compile-time"
version = "0.0.0"
edition = "2024"
publish = false

[dependencies]
pendulum-core = { path = "$root/pendulum-core" }
pendulum-macros = { path = "$root/pendulum-macros" }

[workspace]
TOML
cp "$root/Cargo.lock" "$dir/"
models() { # $1: extra field, e.g. ", algorithm: dense"
    echo "//! Planar 1..16 and spatial 1..8."
    echo "#![allow(missing_docs)]"
    echo "pendulum_macros::model! {"
    for n in $(seq 1 16); do echo "    pub struct Planar$n { kind: planar, links: $n$1 }"; done
    for n in $(seq 1 8); do echo "    pub struct Spatial$n { kind: spatial, links: $n$1 }"; done
    echo "}"
}
seconds() { start=$(date +%s.%N); "$@"; end=$(date +%s.%N); echo "$end - $start" | bc; }
cd "$dir"
export CARGO_TARGET_DIR="$dir/target"
for variant in default dense; do
    if [ $variant = dense ]; then models ", algorithm: dense" > src/lib.rs; else models "" > src/lib.rs; fi
    for profile in dev release; do
        flag=""; [ $profile = release ] && flag="--release"
        cargo build -q $flag
        cargo clean -q -p compile-time $flag
        clean=$(seconds cargo build -q $flag)
        touch src/lib.rs
        incremental=$(seconds cargo build -q $flag)
        echo "$variant algorithms, $profile: clean ${clean} s, incremental ${incremental} s"
    done
done
