# This technique's sample traces, made by scripts/make_samples (sourced: "$nbsim" is the built nbsim,
# "$samples" the folder traces/samples/) from a committed apitrace trace of a real program
# (traces/samples/apitrace/README.md says how each was recorded). Needs apitrace's eglretrace.
# glmark2's "ideas" scene at 160x120 (a desk lamp, a table and flying shapes: about 250 draws a
# frame, lines and discard among them), frames 2 to 21 (0.9 MB).
# Run from the checkout's root, so that the recorded command line (scripts/golden captures it again)
# names the input relative to it.
(cd "$samples/../.." && "$nbsim" capture apitrace traces/samples/apitrace/glmark2_ideas_160x120.trace --frames 2:21 \
  -o traces/samples/apps_glmark2_ideas_160.nbt)
# OpenArena 0.8.8 (GLSL renderer, demo088-test1 at 320x240), frames 1000 to 1004 (4.5 MB). Its
# input is a 900 MB apitrace trace that is not committed; docs/apps.md gives the recording command.
# Made again when NBSIM_OPENARENA_TRACE names such a recording (run from the folder that holds it,
# so that the sample's recorded command line names it as oa.trace).
if [[ -n "${NBSIM_OPENARENA_TRACE:-}" ]]; then
  (cd "$(dirname "$NBSIM_OPENARENA_TRACE")" && "$nbsim" capture apitrace "$(basename "$NBSIM_OPENARENA_TRACE")" --frames 1000:1004 \
    -o "$samples/apps_openarena_320.nbt")
else
  echo "make_samples: traces/samples/apps_openarena_320.nbt kept (set NBSIM_OPENARENA_TRACE to an OpenArena recording to make it again)"
fi
