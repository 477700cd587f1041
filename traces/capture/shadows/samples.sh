# This technique's sample traces, captured by scripts/make_samples (sourced: "$nbsim" is the built
# nbsim, "$samples" the folder traces/samples/). Deterministic for a given Mesa.
# Shadows (docs/shadows.md): the city flown over at 320x240, 4 frames, 2,000 objects, mode clamped (its
# trace also holds GL's infinite reference fill and mask), at two litmap sizes: the litmap side is a
# capture option, so the shadows sweep covers it with one trace per size (2.3 MB and 2.1 MB).
for l in 256 128; do
  "$nbsim" capture shadows --scene city --size 320x240 --frames 4 --path fly --seed 1 --objects 2000 --litmap $l \
    --shadow-mode clamped -o "$samples/shadows_city_fly_320_litmap$l.nbt"
done
