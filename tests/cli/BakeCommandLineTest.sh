#!/usr/bin/env bash
# cairn-bake end to end, as a tools programmer runs it: a level of two objects and two materials, an area
# mapping, the summary and both previews; then bad inputs, each of which must exit 1 with a message naming
# the file and leave no output (nor temporary file) behind.
# Usage: BakeCommandLineTest.sh <cairn-bake> <scratch folder>
set -u
bake="$(realpath "$1")"
work="$2"
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 2
fail() {
    echo "FAIL: $*"
    exit 1
}

# A 24 m x 24 m floor: x < 12 is road, the rest grass
cat >level.obj <<'OBJ'
mtllib level.mtl
v 0 0 0
v 12 0 0
v 12 0 24
v 0 0 24
v 24 0 0
v 24 0 24
o Road
usemtl road
f 1 4 3
f 1 3 2
o Field
usemtl grass
f 2 3 6
f 2 6 5
OBJ
echo '{"default": 0, "materials": {"road": 4}}' >areas.json

"$bake" bake level.obj -o level.navmesh --areas areas.json --summary level.json --preview-obj preview.obj \
    --preview-svg preview.svg >bake.log 2>&1 || fail "the bake failed: $(cat bake.log)"
grep -q "^2 bodies" bake.log || fail "expected one body per object: $(cat bake.log)"
for file in level.navmesh level.json preview.obj preview.svg; do
    [ -s "$file" ] || fail "$file was not written"
done
grep -q "area 4: " preview.svg || fail "the map has no road (area 4)"
grep -q "ground: " preview.svg || fail "the map has no default ground"
grep -q "^f " preview.obj || fail "the OBJ preview has no triangles"

# Part of the level: a box or a list of tiles
"$bake" bake level.obj -o part.navmesh --box 1,1,10,10 >part.log 2>&1 || fail "the box bake failed: $(cat part.log)"
grep -q "baked 1 of 4 tiles" part.log || fail "--box 1,1,10,10 should bake tile (0, 0) alone: $(cat part.log)"
"$bake" bake level.obj -o part.navmesh --tile 1,1 --tile 0,1 >part.log 2>&1 || fail "the tile bake failed"
grep -q "baked 2 of 4 tiles" part.log || fail "two --tile flags should bake two tiles: $(cat part.log)"

# Bad inputs: exit code 1, the file named, nothing written
expect_error() { # <what the message names> <output file> <arguments...>
    local named="$1" output="$2"
    shift 2
    local message
    message=$("$bake" "$@" 2>&1)
    local code=$?
    [ "$code" -eq 1 ] || fail "$* exited with $code, expected 1"
    echo "$message" | grep -qF -- "$named" || fail "$* did not name $named: $message"
    [ ! -e "$output" ] || fail "$* left $output behind"
}
echo '{"materials": {"road": 99}}' >bad-areas.json
expect_error "bad-areas.json" out1.navmesh bake level.obj -o out1.navmesh --areas bad-areas.json
expect_error "missing-areas.json" out2.navmesh bake level.obj -o out2.navmesh --areas missing-areas.json
printf 'v 0 0 0\nv 1 0 0\nv 1 0 1\nusemtl road\nf 1 2 0\n' >broken.obj
expect_error "broken.obj" out3.navmesh bake broken.obj -o out3.navmesh
expect_error "line 5" out3.navmesh bake broken.obj -o out3.navmesh
printf 'v 0 0 0\nv 1 0 nan\nv 1 0 1\nf 1 2 3\n' >nan.obj
expect_error "nan.obj:2" out4.navmesh bake nan.obj -o out4.navmesh
expect_error "(7, 0)" out5.navmesh bake level.obj -o out5.navmesh --tile 7,0
expect_error "--tile" out5.navmesh bake level.obj -o out5.navmesh --tile a,b
expect_error "--box" out5.navmesh bake level.obj -o out5.navmesh --box 1,2,3
expect_error "not a box" out5.navmesh bake level.obj -o out5.navmesh --box 5,5,1,1
echo "not a navmesh" >junk.navmesh
expect_error "junk.navmesh" merged.navmesh merge junk.navmesh -o merged.navmesh
if ls ./*.tmp* >/dev/null 2>&1; then fail "temporary files left: $(ls ./*.tmp*)"; fi
echo "cairn-bake command line: all checks passed"
