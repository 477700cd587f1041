# This technique's sample traces, captured by scripts/make_samples (sourced: "$nbsim" is the built
# nbsim, "$samples" the folder traces/samples/). Deterministic for a given Mesa.
# Layered depth images (docs/ldi.md): three nested shells (d = 6) in a 128 x 128 LDI, 2 frames (frame 1
# rotated), 8x8 viewpoint grid, 4,096 test points a frame (0.5 MB; the 23,040-vertex knot would be
# 4.2 MB, its transform-feedback clip positions repeated in every peel pass). The observer is unused.
"$nbsim" capture ldi --scene boxes --boxes 0 --path fly --size 8x8 --frames 2 --seed 1 --shape nested --shape-param 3 \
  --ldi-size 128 --grid 8x8 --max-layers 64 --points 4096 -o "$samples/ldi_nested_128.nbt"
