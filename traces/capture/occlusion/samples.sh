# This technique's sample traces, captured by scripts/make_samples (sourced: "$nbsim" is the built
# nbsim, "$samples" the folder traces/samples/). Deterministic for a given Mesa.
# The walkthrough: 512x512, 60 frames, GLSL N-buffer culling over the BVH, levels every 10th frame.
"$nbsim" capture occlusion_culling --scene city --size 512x512 --frames 60 --path walk --seed 1 --objects 6000 --mode nb_hier \
  --levels-every 10 -o "$samples/city_walk_512.nbt"
# The flyover (the covering's culling ladder, pipeline/sweeps/nbuffer_covering.json): 512x512, 12
# frames of the fly path over the same city, GLSL N-buffer over the BVH, no levels recorded (8.8 MB).
"$nbsim" capture occlusion_culling --scene city --size 512x512 --frames 12 --path fly --seed 1 --objects 6000 --mode nb_hier \
  --levels-every 0 -o "$samples/city_fly_512.nbt"
# A small one for tests: flat occlusion queries (bounding boxes rasterized by GL), every frame's levels.
"$nbsim" capture occlusion_culling --scene city --size 128x96 --frames 8 --path walk --seed 3 --objects 1200 --mode oq \
  --levels-every 0 -o "$samples/city_small_oq.nbt"
"$nbsim" capture occlusion_culling --scene city --size 128x96 --frames 8 --path fly --seed 3 --objects 1200 --mode nb \
  --levels-every 1 --reversed-z -o "$samples/city_small_nb_reversed.nbt"
