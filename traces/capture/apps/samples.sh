# This technique's sample trace, made by scripts/make_samples (sourced: "$nbsim" is the built nbsim,
# "$samples" the folder traces/samples/) from a committed apitrace trace of a real program
# (traces/samples/apitrace/README.md says how each was recorded). Needs apitrace's eglretrace.
# glmark2's "ideas" scene at 160x120 (a desk lamp, a table and flying shapes: about 250 draws a
# frame, lines and discard among them), frames 2 to 21 (0.9 MB).
# Run from the checkout's root, so that the recorded command line (scripts/golden captures it again)
# names the input relative to it.
(cd "$samples/../.." && "$nbsim" capture apitrace traces/samples/apitrace/glmark2_ideas_160x120.trace --frames 2:21 \
  -o traces/samples/apps_glmark2_ideas_160.nbt)
