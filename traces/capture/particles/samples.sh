# This technique's sample traces, captured by scripts/make_samples (sourced: "$nbsim" is the built
# nbsim, "$samples" the folder traces/samples/). Deterministic for a given Mesa.
# Particles (docs/particles.md): the walk at 256x256, 16 frames, 10,000 sprites of 16 px culled by the GLSL
# N-buffer (mode nb). The model replays a trace in its capture's mode, so nb is the mode whose
# N-buffer designs (level cap, resolution, format, update policy) a sweep can vary on it.
"$nbsim" capture particles --scene city --size 256x256 --frames 16 --path walk --seed 1 --particles 10000 --sprite 16 \
  --mode nb -o "$samples/particles_walk_256.nbt"
