# This technique's step of scripts/demo (sourced, in the registration list's order, with "$nbsim" the
# built nbsim, "$out" the demo's output folder, "$step" the step's number; run from the repository's
# root). A failure is reported and the demo goes on.
echo "== $step. Shadows: fill per frame beside the paper's ratios (traces/samples/shadows_city_fly_320_litmap256.nbt, the other modes and scenes, and the paper's observer on the ground)"
# The sample is the city in mode clamped; the model replays a trace in its capture's mode, so the other
# rows are captures at the sample's arguments (scripts/make_samples; --objects is the city's own):
# the city in modes infinite and culled, the boxes and the terrain in every mode (about 15 s on
# llvmpipe, kept in OUT/shadows/traces and reused). A capture that fails leaves its row out.
straces=()
for s in boxes terrain city; do
  for m in infinite culled clamped; do
    if [[ $s == city && $m == clamped ]]; then straces+=(traces/samples/shadows_city_fly_320_litmap256.nbt); continue; fi
    t=$out/shadows/traces/shadows_${s}_fly_320_$m.nbt
    extra=()
    [[ $s == city ]] && extra=(--objects 2000)
    mkdir -p "$out/shadows/traces"
    if [[ -f "$t" ]] || { "$nbsim" capture shadows --scene "$s" "${extra[@]}" --size 320x240 --frames 4 --path fly --seed 1 \
         --litmap 256 --shadow-mode "$m" -o "$t.part" > /dev/null && mv "$t.part" "$t"; }; then
      straces+=("$t")
    else
      echo "shadows: the capture of $s in mode $m failed (see above); its row is left out"
    fi
  done
done
# The paper's set-up: an observer on the ground at 640x480 (the birds above the view, their shadows in
# it), each scene clamped, 10 frames (about 10 s on llvmpipe, kept and reused like the others).
for s in boxes terrain city; do
  t=$out/shadows/traces/shadows_${s}_ground_640_clamped.nbt
  mkdir -p "$out/shadows/traces"
  if [[ -f "$t" ]] || { "$nbsim" capture shadows --scene "$s" --path ground --size 640x480 --frames 10 --shadow-mode clamped \
       -o "$t.part" > /dev/null && mv "$t.part" "$t"; }; then
    straces+=("$t")
  else
    echo "shadows: the ground-path capture of $s failed (see above); its row is left out"
  fi
done
# Exit status 1: a mask pixel differs somewhere; other non-zero: a replay failed. The rest is still written.
"$nbsim" shadows "${straces[@]}" --out "$out/shadows" || echo "shadows: a mask pixel differs or a replay failed (see above)"
