#!/usr/bin/env bash
# output_matrix.sh BIN DIR: runs a fixed matrix of commands with BIN and
# leaves every file they write (and what they print, timings removed) in
# DIR, so a refactor can prove itself: run it with the binary before and
# after the change into two directories, then
#
#   tools/output_matrix.sh compare DIR_BEFORE DIR_AFTER
#
# cmp's every file and prints how many are identical. The commands run
# inside DIR with relative names, so the command lines recorded in the
# provenance are the same whatever DIR is. The matrix: the golden cases,
# rock06 at scale 64 (periodic and --clamp, 1 and 2 threads, --basis dirs:6,
# every output kind, PNG/TGA/EXR/TIFF, 16-bit and mips), inter-reflection
# (the map's own level and the coarse one), a batch with a
# depfile, and every other command once or twice.
set -uo pipefail

if [ "${1:-}" = compare ]; then
  a=${2:?usage: output_matrix.sh compare DIR_A DIR_B} b=${3:?usage: output_matrix.sh compare DIR_A DIR_B}
  total=0 same=0 differ=()
  while IFS= read -r -d '' f; do
    rel=${f#"$a"/}
    total=$((total + 1))
    if [ -f "$b/$rel" ] && cmp -s "$f" "$b/$rel"; then same=$((same + 1)); else differ+=("$rel"); fi
  done < <(find "$a" -type f ! -path "$a/in/*" -print0 | sort -z)
  extra=$(cd "$b" && find . -type f ! -path './in/*' | sed 's|^\./||' | while read -r rel; do
    [ -f "$a/$rel" ] || echo "$rel"; done)
  echo "output_matrix: $total files compared, $same identical"
  for d in "${differ[@]}"; do echo "  differs or missing: $d"; done
  [ -n "$extra" ] && printf '  only in %s: %s\n' "$b" $extra
  [ "$same" = "$total" ] && [ -z "$extra" ]
  exit
fi

bin=$(realpath "${1:?usage: output_matrix.sh BIN DIR}")
dir=${2:?usage: output_matrix.sh BIN DIR}
root=$(cd "$(dirname "$0")/.." && pwd)
rm -rf "$dir" && mkdir -p "$dir/in" "$dir/out" && cd "$dir" || exit 1
cp "$root"/fixtures/*.png "$root"/fixtures/rivet_panel.obj in/
rock=in/rock06_height.png
failures=0

# run NAME ARGS...: runs BIN ARGS, keeping stdout and stderr (with the
# JSON "seconds" object and "done in" timings taken out) and the exit code.
run() {
  local name=$1
  shift
  "$bin" "$@" >"out/$name.stdout" 2>"out/$name.stderr"
  echo $? >"out/$name.rc"
  sed -i -e 's/"seconds":{[^}]*}/"seconds":{}/' -e 's/in [0-9.]* s/in X s/' \
    "out/$name.stdout" "out/$name.stderr"
}

# The golden cases (fixtures/goldens/cases.txt).
run g_noise16 bake in/noise_96x80.png --scale 16 --normal out/g_noise16_normal.exr \
  --weights out/g_noise16_weights.exr --ssbump out/g_noise16_ssbump.exr --ao out/g_noise16_ao.exr \
  --bent out/g_noise16_bent.exr --filtered out/g_noise16_filtered.exr
run g_bricks bake in/bricks_128x64.png --scale 8 --clamp --power 2 --basis hl2+z \
  --normal out/g_bricks_normal.exr --ssbump out/g_bricks_ssbump.exr --ao out/g_bricks_ao.exr \
  --bent out/g_bricks_bent.exr
run g_pit bake in/pit_65x65.png --scale 16 --filter-radius 0 --rays 64 --normal out/g_pit_normal.exr \
  --ssbump out/g_pit_ssbump.exr --ao out/g_pit_ao.exr --bent out/g_pit_bent.exr --filtered out/g_pit_filtered.exr
run g_rock32 bake in/rock06_128.png --scale 32 --normal out/g_rock32_normal.exr \
  --weights out/g_rock32_weights.exr --ssbump out/g_rock32_ssbump.exr --ao out/g_rock32_ao.exr \
  --bent out/g_rock32_bent.exr
mkdir -p h2s && cp in/bricks_128x64.png h2s/
run g_h2s height2ssbump -r 64 h2s/bricks_128x64.png 8

# rock06 at scale 64: every kind, each format, both addressings, 1 and 2 threads.
for t in 1 2; do
  run rock_p$t bake $rock --scale 64 --threads $t --normal out/rock_p${t}_normal.png \
    --weights out/rock_p${t}_weights.tga --ssbump out/rock_p${t}_ssbump.png --ao out/rock_p${t}_ao.tif \
    --bent out/rock_p${t}_bent.exr --filtered out/rock_p${t}_filtered.png --json
  run rock_c$t bake $rock --scale 64 --clamp --threads $t -o out/rock_c$t
done
run rock_dirs6 bake $rock --scale 64 --basis dirs:6 --ssbump out/rock_dirs6_ssbump.exr \
  --weights out/rock_dirs6_weights.tif
run rock_16 bake $rock --scale 64 --depth 16 --normal out/rock_16_normal.png --ao out/rock_16_ao.tif
run rock_mips bake $rock --scale 64 --mips --normal out/rock_mips_normal.tif --ssbump out/rock_mips_ssbump.exr
run rock_half bake $rock --scale 64 --depth half --ao out/rock_half_ao.exr --rays 64 --normal-y up \
  --bent out/rock_half_bent.exr
# Engine textures: VTF and DDS in each block format and fit, 1 and 2 threads,
# a thin strip (its levels down to 1 x 1 are rows of half blocks) and a
# Source material.
for t in 1 2; do
  run tex_vtf$t bake $rock --scale 64 --threads $t --ssbump out/tex_vtf${t}_ssbump.vtf \
    --normal out/tex_vtf${t}_normal.vtf --vtf-version 7.3 --vmt out/tex_vtf$t.vmt --materials out
  run tex_dds$t bake $rock --scale 64 --threads $t --ssbump out/tex_dds${t}_ssbump.dds \
    --normal out/tex_dds${t}_normal.dds --ao out/tex_dds${t}_ao.dds
done
run tex_fast bake $rock --scale 64 --ssbump out/tex_fast_ssbump.vtf --normal out/tex_fast_normal.dds \
  --texture-format bc1 --fast-compression
run tex_bc3 height2ssbump -A in/rock06_128.png 16 -o out/tex_h2s.vtf
oiiotool $rock --cut 1024x16+0+0 --resize 4096x16 -o in/strip.png
run tex_strip bake in/strip.png --scale 64 --ssbump out/tex_strip_ssbump.vtf \
  --bent out/tex_strip_bent.dds --texture-format bc1
run rock_slope bake in/rock06_128.png --scale 16 --slope out/rock_slope.png --lit 135,45
# Inter-reflection: on the map's own level (under 512 texels; converged,
# then one bounce with an albedo map) and on the coarse level (1024).
run bounce_own bake in/rock06_128.png --scale 32 --bounce 0.5 --ao out/bounce_own_ao.exr \
  --ssbump out/bounce_own_ssbump.exr --bent out/bounce_own_bent.exr
run bounce_one bake in/noise_96x80.png --scale 16 --bounce 0.6 --bounces 1 --threads 1 \
  --bounce-albedo in/noise_96x80.png --ao out/bounce_one_ao.exr
run bounce_coarse bake $rock --scale 64 --bounce 0.5 --ao out/bounce_coarse_ao.exr \
  --ssbump out/bounce_coarse_ssbump.exr
run normal normal in/rock06_128.png --scale 16 -o out/normal.png --normal-filter valve
run normal_up normal in/noise_96x80.png --scale 8 -o out/normal_up.tga --normal-y up

# A batch with a depfile, then again (everything up to date).
mkdir -p batch_in batch_out
cp in/noise_96x80.png in/pit_65x65.png in/rock06_128.png batch_in/
run batch1 bake batch_in --scale 16 --out-dir batch_out --maps normal,ao,filtered --depfile out/batch.d --json
run batch2 bake batch_in --scale 16 --out-dir batch_out --maps normal,ao,filtered
run batch_name bake batch_in/noise_96x80.png --scale 8 --out-dir batch_out --name '{kind}-{stem}.{ext}.tif'
run single_dep bake in/pit_65x65.png --scale 8 --ao out/dep_ao.png --depfile out/single.d

# Valve's tools and conversions.
mkdir -p h2s2 && cp in/rock06_128.png h2s2/rock.png
run h2s_n height2ssbump -n -A h2s2/rock.png 16
run h2s_d height2ssbump -d -D h2s2/rock.png 16
run n2s normal2ssbump out/normal.png -o out/n2s.png
run s2n ssbump2normal out/rock_p1_ssbump.png -o out/s2n.png
run comb_mix combine out/rock_p1_ssbump.png out/rock_p2_ssbump.png --mix 0.3 -o out/comb_mix.png
run comb_det combine out/rock_p1_normal.png out/rock_c1_normal.png --detail --kind normal -o out/comb_det.exr
run program program 'addnormals(out/normal.png, heightmap(in/rock06_128.png, 4))' -o out/program.png
run program_mips program 'invertColor(in/noise_96x80.png)' -o out/program_mips.tif --mips

# Renders.
run render_ss render --ssbump out/rock_p1_ssbump.png --light 30,40 -o out/render_ss.png
run render_h render in/rock06_128.png --scale 16 --mode ao --specular 32 -o out/render_h.exr
run render_cmp render --normal out/rock_p1_normal.png --ssbump out/rock_p1_ssbump.png \
  --ao out/rock_p1_ao.tif --compare --crop 0,0,256,256 -o out/render_cmp.png
run render_orbit render --ssbump out/g_rock32_ssbump.exr --orbit 3 --tile 2 -o out/orbit.png
run render_gif render --ssbump out/g_rock32_ssbump.exr --orbit 3 -o out/orbit.gif
run sheet sheet in/rock06_128.png --scale 16 -o out/sheet.png --panel-size 64
run rbf renderbumpflat -size 128 64 in/rivet_panel.obj -o out/rbf_local.tga --height out/rbf_height.png
run rbf_tile renderbumpflat --size 64 64 in/rivet_panel.obj --rect 0 0 1 1 --tile -o out/rbf_tile.exr \
  --axis -y --samples 2
run rbf_exr renderbumpflat -size 32 24 in/rivet_panel.obj -o out/rbf_exr.tif --height out/rbf_exr_h.exr \
  --normal-y up -q
run rbf_tga renderbumpflat -size 32 32 in/rivet_panel.obj -o out/rbf_tga.png --height out/rbf_tga_h.tga
mkdir -p rbf_dir && cp in/rivet_panel.obj rbf_dir/
printf 'mtllib missing.mtl\n' | cat - in/rivet_panel.obj >rbf_dir/rivet_mtl.obj
run rbf_default renderbumpflat -size 16 16 rbf_dir/rivet_panel.obj
run rbf_mtl renderbumpflat -size 16 16 rbf_dir/rivet_mtl.obj --height rbf_dir/rivet_mtl_h.tif
printf 'v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 3\n' >in/flat.obj
run rbf_flat renderbumpflat -size 8 8 in/flat.obj -o out/rbf_flat.png --height out/rbf_flat_h.png
run err_rbf_same renderbumpflat in/rivet_panel.obj -o out/rbf_same.png --height out/./rbf_same.png
run err_rbf_ext renderbumpflat in/rivet_panel.obj --height out/rbf_h.jpg
run err_rbf_gif renderbumpflat in/rivet_panel.obj -o out/rbf.gif
run err_rbf_dir renderbumpflat in/rivet_panel.obj -o out/nowhere/rbf.png

# What it prints about files.
run info info out/rock_p1_normal.png out/g_noise16_ao.exr out/rbf_local.tga
run info_json info --json out/rock_mips_ssbump.exr out/orbit_001.png
run compare compare out/rock_p1_ssbump.png out/rock_p2_ssbump.png
run compare2 compare out/rock_p1_ao.tif out/rock_16_ao.tif --json --diff out/compare_diff.exr
run compare3 compare out/normal.png out/rock_c1_normal.png -failpercent 50
run compare_png compare out/rock_p1_ao.tif out/rock_16_ao.tif --diff out/compare_diff.png -q
run compare_tif compare out/rock_p1_normal.png out/rock_c1_normal.png --diff out/compare_diff.tif
run compare_same compare out/rock_p1_ao.tif out/rock_p1_ao.tif --diff out/compare_same.exr
run err_diff_over compare out/rock_p1_ao.tif out/rock_16_ao.tif --diff out/../out/rock_16_ao.tif
run err_diff_ext compare out/rock_p1_ao.tif out/rock_16_ao.tif --diff out/diff.jpg
run err_diff_gif compare out/rock_p1_ao.tif out/rock_16_ao.tif --diff out/diff.gif
run err_n2s_gif normal2ssbump out/normal.png -o out/n2s.gif

# Errors: messages and exit codes.
run err_scale bake $rock --ao out/x.png
run err_same bake $rock --scale 4 --ao out/x.png --ssbump out/x.png
run err_ext bake $rock --scale 4 --ao out/x.jpg
run err_missing bake in/missing.png --scale 4 --ao out/x.png
run err_over bake $rock --scale 4 --ao $rock
echo "output_matrix: $(find out batch_out h2s h2s2 rbf_dir -type f | wc -l) files in $dir"
