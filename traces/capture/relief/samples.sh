# This technique's sample traces, captured by scripts/make_samples (sourced: "$nbsim" is the built
# nbsim, "$samples" the folder traces/samples/). Deterministic for a given Mesa.
# Relief textures (docs/relief.md): an fBm terrain of 64 x 64 texels in a box of height 0.25, seen at 128 x 128 from
# 0, 45, 80 and 89 degrees off its up axis (one frame each), every method a box draw (0.7 MB).
"$nbsim" capture relief --scene boxes --boxes 0 --path fly --size 128x128 --frames 4 --seed 3 --field fbm --field-size 64 \
  --angles 0,45,80,89 -o "$samples/relief_fbm_64.nbt"
