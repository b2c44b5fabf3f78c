#!/bin/sh
# An installed copy in a fresh prefix, moved away from the build and source trees, finds its
# plotting script and draws, also into a folder whose name has a quote and a space (the
# plots run without a shell), and loads the gmsh module installed with it.
# Usage: installed_copy_draws.sh BUILD_DIR
set -eu
build="$1"
prefix=$(mktemp -d)
trap 'rm -rf "$prefix"' EXIT
cmake --install "$build" --prefix "$prefix/p" >/dev/null
mv "$prefix/p" "$prefix/moved"
p="$prefix/moved"
out="$prefix/it's a folder"
"$p/bin/shroudsim" frf "$p/share/shroudsim/examples/lumped_jenkins.toml" --quiet --out "$out"
for f in frf.png loops.png; do
  test -s "$out/$f" || { echo "installed_copy_draws: $out/$f missing" >&2; exit 1; }
done
grep -q '"drawn": true' "$out/run.json" || { echo "installed_copy_draws: run.json says the plots were not drawn" >&2; exit 1; }
# It loads its own gmsh module (installed beside it, found after the move), once it needs one.
(cd "$prefix" && "$p/bin/shroudsim" mesh "$p/share/shroudsim/examples/shrouded_blade.toml" --quiet --out "$prefix/m" \
  --set geometry.mesh_size=0.03 --set geometry.element_order=1)
grep -q "\"gmsh_module\": \"$p/" "$prefix/m/run.json" ||
  { echo "installed_copy_draws: the mesh was not made by the installed gmsh module:" >&2;
    grep gmsh_module "$prefix/m/run.json" >&2; exit 1; }
echo "installed_copy_draws: ok"
