#!/bin/bash
# The f64 reference's node visits per walk and per pixel (the probe patch's
# tree_work example), 480x270, for each tree, scene and view.
# Run from a checkout of 727b527 with tree-probes.patch applied, after
# cargo build --release -p twinray-common --example tree_work.
cp -r "$(dirname "$0")/views" views  # the views beside this script, copied to the checkout root
run() { r=$(env "$@" target/release/examples/tree_work ${SC:-teapot} 480x270 2>&1 | sed 's/build [0-9.]*m\?s//; s/^teapot [0-9x]* in [0-9.]*m\?s: //; s/^.*\.toml [0-9x]* in [0-9.]*m\?s: //' | tr '\n' ' '); echo "$* | ${SC:-teapot} ${TQ_SET:-}: $r"; }
for cfg in "X=1" "TQ_BIG=4096 TQ_BINS_BIG=32" "TQ=opt" "TQ=opt TQ_BIG=4096 TQ_BINS_BIG=32" "TQ=opt TQ_BIG=4096 TQ_BINS_BIG=32 TQ_TC=1.5" "TQ_BIG=4096 TQ_BINS_BIG=32 TQ_TC=1.5" "TQ=sweep" "TQ=sweep,opt" "TQ_BINS=32" "TQ_BINS=64" "TQ=reinsert"; do
  for t in 20x15 40x30 80x60 160x120; do TQ_SET=tessellation=$t run $cfg; done
  for v in side top back low close; do SC=views/$v.toml run $cfg; done
done
