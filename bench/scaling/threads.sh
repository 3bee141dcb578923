#!/bin/sh
# Parallel efficiency of each technique: the same work per thread at 1 and N
# threads (weak scaling: spp grows with the thread count), efficiency =
# time(1 thread) / time(N threads). Radiosity: a fixed problem, speed-up.
#   bench/scaling/threads.sh [BINARY] [N]    (default target/release/tracelab, 16)
BIN=${1:-target/release/tracelab}
N=${2:-16}
OUT=${OUT:-/tmp}
run() { # threads spp scene integrator
  case $3 in *.xml) size="-D resx=256 -D resy=256" ;; *) size="" ;; esac
  $BIN render $3 --integrator $4 $size --threads $1 --spp $2 --out $OUT/scaling.exr 2>&1 |
    grep '^spp' | grep -o '| [0-9.]* s |' | head -1 | tr -d '| s'
}
echo "technique scene spp_per_thread t1_s tN_s efficiency"
for spec in "path scenes/cornell_box.toml 16" "bdpt scenes/cornell_box.toml 4" \
            "vcm scenes/cornell_box.toml 4" "sppm scenes/caustic.toml 32" \
            "path scenes/veach-bidir/scene.xml 16" "bdpt scenes/veach-bidir/scene.xml 4"; do
  set -- $spec
  t1=$(run 1 $3 $2 $1)
  tn=$(run $N $(($3 * N)) $2 $1)
  echo "$1 $2 $3 $t1 $tn $(echo "$t1 $tn" | awk '{ if ($2 > 0) printf "%.2f", $1 / $2 }')"
done
# The Cornell box, and the sphere room of 100 000 triangles, where the
# clusters' links and the backs' exposure rays add work of their own.
for spec in "scenes/cornell_box.toml --epsilon 1e-5 --patch-size 0.002" \
            "scenes/cluster_room.toml --patch-size 0.02"; do
  set -- $spec
  for t in 1 $N; do
    start=$(date +%s.%N)
    $BIN render "$@" --integrator radiosity --solver hierarchical \
        --threads $t --out $OUT/r.png >/dev/null 2>&1
    echo "radiosity-hierarchical $1 threads=$t wall_s=$(echo "$start $(date +%s.%N)" | awk '{printf "%.3f", $2 - $1}')"
  done
done
