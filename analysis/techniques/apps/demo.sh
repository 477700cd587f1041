# This technique's step of scripts/demo (sourced, in the registration list's order, with "$nbsim" the
# built nbsim, "$out" the demo's output folder, "$step" the step's number; run from the repository's
# root). A failure is reported and the demo goes on.
echo "== $step. A real program: OpenArena's draw calls culled in every mode (traces/samples/apps_openarena_320.nbt)"
# Exit status 1 means a false cull somewhere: report it, but still write the rest.
"$nbsim" table2 traces/samples/apps_openarena_320.nbt --out "$out/apps" || echo "apps: some mode had false culls (see above)"
