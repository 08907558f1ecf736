#!/bin/sh
# Regenerates the gallery images in docs/gallery with the `pendulum` command, exactly as
# the README shows them. Run from anywhere: sh docs/gallery/make.sh
# (PENDULUM=path/to/pendulum sh docs/gallery/make.sh uses that binary instead).
set -eu
root="$(cd "$(dirname "$0")/../.." && pwd)"
cd "$root"
if [ -n "${PENDULUM:-}" ]; then
    pendulum() { "$PENDULUM" "$@"; }
else
    cargo build --release -q -p pendulum-cli
    pendulum() { cargo run --release -q -p pendulum-cli -- "$@"; }
fi
runs="$(mktemp -d)"
trap 'rm -rf "$runs"' EXIT
gallery=docs/gallery

# The demo: a triple pendulum released from 1 rad (chaotic), 10 s.
pendulum simulate --out "$runs/triple" --frames 80 --quiet
cp "$runs/triple/chain.gif" "$gallery/triple.gif"
cp "$runs/triple/energy.png" "$gallery/triple-energy.png"

# Kapitza's pendulum: released near the top, held upright by a fast vertical drive
# (a²ω² = 16 m²/s² > 2gl = 3.9 m²/s²). Its first half second (one slow swing about the
# top) drawn again at 8 frames per drive period, in slow motion.
pendulum simulate --n 1 --lengths 0.2 --initial tilted:2.9 --drive harmonic --amplitude 0.02 \
    --omega 200 --step 0.0005 --end 4 --out "$runs/kapitza" --quiet
pendulum render "$runs/kapitza" --from 0 --to 0.5 --frames 251 --out "$gallery/kapitza.gif" --quiet
cp "$runs/kapitza/energy.png" "$gallery/kapitza-energy.png"

# A hanging 12-link chain whirled by its pivot on a horizontal circle (3D): the side view
# simulate draws, then the same run drawn again from above and turning with the pivot.
pendulum simulate --dim 3 --n 12 --lengths 0.1 --initial hanging --drive circle --radius 0.08 \
    --omega 5 --step 0.001 --end 10 --every 10 --frames 100 --view xz --out "$runs/whirl" --quiet
cp "$runs/whirl/chain.gif" "$gallery/whirl-side.gif"
pendulum render "$runs/whirl" --view top --out "$gallery/whirl-top.gif" --quiet
pendulum render "$runs/whirl" --view co-rotating --out "$gallery/whirl-co-rotating.gif" --quiet

# A damped double pendulum: the energy falls by exactly the dissipated energy.
pendulum simulate --n 2 --damping 0.05 --initial horizontal --end 20 --out "$runs/damped" --quiet
cp "$runs/damped/energy.png" "$gallery/damped-energy.png"
# Normal modes of a uniform 12-link chain, and its steady rotating shapes.
pendulum modes --n 12 --lengths 0.1 --count 4 --out "$runs/modes" > /dev/null
cp "$runs/modes/modes.png" "$gallery/modes.png"
pendulum steady --n 12 --lengths 0.1 --omega 5,10,15 --out "$runs/steady" > /dev/null
cp "$runs/steady/branches.png" "$gallery/steady-branches.png"
cp "$runs/steady/shapes.png" "$gallery/steady-shapes.png"
# Whirl a chain (README "Whirl a chain"): 100 links, L = 1 m, M = 1 kg, hanging at rest,
# the pivot on a 2 cm circle, light damping. A sudden start at 3, 6 and 11 rad/s.
whirl="--dim 3 --n 100 --masses 0.01 --lengths 0.01 --damping 3e-4 --initial hanging \
    --drive circle --radius 0.02 --integrator rk4 --step 0.001 --every 100"
for w in 3 6 11; do
    pendulum simulate $whirl --omega "$w" --end 150 --out "$runs/whirl-$w" --quiet > "$runs/whirl-$w.txt"
    cp "$runs/whirl-$w/shape.png" "$gallery/whirl-$w-shape.png"
done
# The same chain at 5 rad/s: sudden start, and the speed ramped up from 0 over 150 s.
pendulum simulate $whirl --omega 5 --end 400 --out "$runs/sudden-5" --quiet > "$runs/sudden-5.txt"
cp "$runs/sudden-5/shape.png" "$gallery/whirl-5-sudden-shape.png"
pendulum simulate $whirl --omega 5 --ramp-time 150 --end 400 --out "$runs/ramp-5" --quiet > "$runs/ramp-5.txt"
cp "$runs/ramp-5/shape.png" "$gallery/whirl-5-ramp-shape.png"
pendulum render "$runs/ramp-5" --view co-rotating --from 0 --to 250 --speed 10 --frames 250 \
    --out "$gallery/whirl-5-ramp-co-rotating.gif" --quiet
# The chain's choice against ω: 20 links, 24 speeds, three kinds of experiment (about 20 s
# with 2 cores).
pendulum sweep --n 20 --lengths 0.05 --masses 0.05 --radius 0.02 --damping 5.6237e-4 \
    --omega 0.5:5:24 --scaled --kind sudden,ramp-up,ramp-down --duration 600 --ramp-time 200 \
    --out "$runs/sweep" --quiet > "$runs/sweep.txt"
cp "$runs/sweep/sweep.png" "$gallery/sweep.png"
# The chain's choice over ω and R: 32 × 32 sudden starts (about 2.5 min with 2 cores), and
# 16 × 16 sudden and ramped side by side (about 75 s).
pendulum atlas --n 20 --lengths 0.05 --masses 0.05 --damping 5.6237e-4 --omega 0.5:5:32 --scaled \
    --radius 0.005:0.05:32 --duration 600 --out "$runs/atlas" --quiet > "$runs/atlas.txt"
cp "$runs/atlas/atlas.png" "$gallery/atlas.png"
pendulum atlas --n 20 --lengths 0.05 --masses 0.05 --damping 5.6237e-4 --omega 0.5:5:16 --scaled \
    --radius 0.005:0.05:16 --kind sudden,ramp-up --ramp-time 200 --duration 600 \
    --out "$runs/atlas-kinds" --quiet > "$runs/atlas-kinds.txt"
cp "$runs/atlas-kinds/atlas.png" "$gallery/atlas-kinds.png"
# The viewer (needs chromium for the screenshot): the 6 rad/s whirl with the defaults, 300 s.
pendulum simulate --dim 3 --n 100 --masses 0.01 --lengths 0.01 --damping 3e-4 --initial hanging \
    --drive circle --radius 0.02 --omega 6 --end 300 --out "$runs/whirl-6-defaults" --quiet > /dev/null
pendulum view "$runs/whirl-6-defaults" --export "$runs/whirl-6-defaults.html"
chromium --headless --no-sandbox --disable-gpu --window-size=1200,800 --virtual-time-budget=3000 \
    --screenshot="$gallery/view.png" "file://$(cd "$runs" && pwd)/whirl-6-defaults.html#t=500"
# The live page (needs chromium): the whirl's chain 120 s into its motion, the pivot
# dragged by (120, −60) px half a second after the page opens, 6 s on.
# (the binary itself, not `cargo run`, so that Ctrl-C reaches the server)
"${PENDULUM:-$root/target/release/pendulum}" view --live --port 0 --start 120 2> "$runs/live.log" &
server=$!
sleep 3
url="$(grep -o 'http://[0-9.:]*/' "$runs/live.log")"
chromium --headless --no-sandbox --disable-gpu --window-size=1200,800 --virtual-time-budget=10000 \
    --user-data-dir="$runs/profile" --screenshot="$gallery/live.png" "${url}#drag&hold=6"
kill -INT "$server"
cat "$runs"/whirl-3.txt "$runs"/whirl-6.txt "$runs"/whirl-11.txt "$runs"/sudden-5.txt "$runs"/ramp-5.txt
ls -l "$gallery"
