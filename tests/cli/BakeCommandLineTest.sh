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

# An off-mesh link (a one-way drop across the floor's two tiles): in the navmesh, drawn on the map
echo '{"links": [{"start": [2, 0, 2], "end": [20, 0, 20], "bidirectional": false, "user_id": 9}]}' >links.json
"$bake" bake level.obj -o linked.navmesh --areas areas.json --links links.json --preview-svg linked.svg \
    >linked.log 2>&1 ||
    fail "the bake with links failed: $(cat linked.log)"
grep -q 'marker-end="url(#arrow)"' linked.svg || fail "the map has no link arrow"
cmp -s level.navmesh linked.navmesh && fail "the link left the navmesh as it was"
grep -q "off-mesh links: 1, 0 that no agent can take" linked.log || fail "the link was not checked: $(cat linked.log)"
# A link whose end is 5 m above the floor: baked, with a warning that no agent can take it
echo '{"links": [{"start": [2, 0, 2], "end": [20, 5, 20], "user_id": 9}]}' >dead-links.json
"$bake" bake level.obj -o dead.navmesh --links dead-links.json >dead.log 2>&1 || fail "the dead link's bake failed"
grep -q "warning: off-mesh link (user id 9) .*its end joins no navmesh" dead.log ||
    fail "no warning for a link no agent can take: $(cat dead.log)"
grep -q "off-mesh links: 1, 1 that no agent can take" dead.log || fail "the dead link was not counted: $(cat dead.log)"

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
echo '{"links": [{"start": [2, 0, 2], "end": [20, 0]}]}' >bad-links.json
expect_error "bad-links.json: link 0: 'end' must be three numbers" out2.navmesh bake level.obj \
    -o out2.navmesh --links bad-links.json
echo '{"links": [{"start": [2, 0, 2], "end": [200, 0, 20]}]}' >far-links.json
expect_error "off-mesh link 0: its end" out2.navmesh bake level.obj -o out2.navmesh --links far-links.json
printf 'v 0 0 0\nv 1 0 0\nv 1 0 1\nusemtl road\nf 1 2 -9\n' >broken.obj
expect_error "broken.obj" out3.navmesh bake broken.obj -o out3.navmesh
expect_error "broken.obj:5:" out3.navmesh bake broken.obj -o out3.navmesh
printf 'v 0 0 0\nv 1 0 nan\nv 1 0 1\nf 1 2 3\n' >nan.obj
expect_error "nan.obj:2" out4.navmesh bake nan.obj -o out4.navmesh
expect_error "(7, 0)" out5.navmesh bake level.obj -o out5.navmesh --tile 7,0
expect_error "--tile" out5.navmesh bake level.obj -o out5.navmesh --tile a,b
expect_error "--box" out5.navmesh bake level.obj -o out5.navmesh --box 1,2,3
expect_error "not a box" out5.navmesh bake level.obj -o out5.navmesh --box 5,5,1,1
echo "not a navmesh" >junk.navmesh
expect_error "junk.navmesh" merged.navmesh merge junk.navmesh -o merged.navmesh
expect_error "--shard 1/-1" out5.navmesh bake level.obj -o out5.navmesh --shard 1/-1
# Folders and fields of the wrong type were exceptions that aborted the baker
mkdir -p a-folder
expect_error "a-folder: not a readable file" out5.navmesh bake level.obj -o out5.navmesh --config a-folder
expect_error "a-folder: not a readable file" out5.navmesh bake level.obj -o out5.navmesh --areas a-folder
expect_error "a-folder: not a readable file" out5.navmesh bake level.obj -o out5.navmesh --previous a-folder \
    --previous-navmesh level.navmesh
expect_error "a-folder: not a readable file" out5.navmesh bake level.obj -o out5.navmesh --previous level.json \
    --previous-navmesh a-folder
echo '{"format": 5, "version": "1", "tiles": {}}' >typed.json
expect_error "typed.json: not a cairn-bake summary" out5.navmesh bake level.obj -o out5.navmesh --previous typed.json \
    --previous-navmesh level.navmesh
echo '{"format": "cairn-bake-summary", "version": 1, "tiles": [{"x": "0", "z": 0}]}' >typed.json
expect_error "typed.json: tiles[0]" out5.navmesh bake level.obj -o out5.navmesh --previous typed.json \
    --previous-navmesh level.navmesh
echo '{"max_verts_per_poly": 4294967299}' >wrap.json
expect_error "max_verts_per_poly" out5.navmesh bake level.obj -o out5.navmesh --config wrap.json

# Outputs are checked before any work: never an input, another output's file, a link or a device
cp level.obj level-before.obj
expect_error "is the input" out6.navmesh bake level.obj -o level.obj --tile 0,0
cmp -s level.obj level-before.obj || fail "-o naming the input changed the level"
expect_error "each output needs a file of its own" out6.navmesh bake level.obj -o out6.navmesh --summary out6.navmesh
expect_error "-o: an empty path" out6.navmesh bake level.obj -o ""
ln -s link-target.navmesh link.navmesh
expect_error "symbolic link" link-target.navmesh bake level.obj -o link.navmesh
[ -L link.navmesh ] || fail "the link was replaced"
mkfifo pipe.navmesh
expect_error "not a regular file" out6.navmesh bake level.obj -o pipe.navmesh
[ -p pipe.navmesh ] || fail "the pipe was replaced"
expect_error "does not exist" no-such-folder/out.navmesh bake level.obj -o no-such-folder/out.navmesh
expect_error "is the input" out6.navmesh merge level.navmesh -o level.navmesh
expect_error "is the input" out6.navmesh bake level.obj -o out6.navmesh --previous level.json \
    --previous-navmesh level.navmesh --summary level.json

# An incremental bake takes the previous navmesh only with its own summary
cat >other.obj <<'OBJ'
v 0 0 0
v 30 0 0
v 30 0 30
v 0 0 30
f 1 3 2
f 1 4 3
OBJ
"$bake" bake other.obj -o other.navmesh --summary other.json >/dev/null 2>&1 || fail "the other level's bake failed"
expect_error "from different bakes" out7.navmesh bake level.obj -o out7.navmesh --previous level.json \
    --previous-navmesh other.navmesh

# merge with the shards' summaries notices a missing shard (without them it can only warn)
for k in 0 1 2; do
    "$bake" bake level.obj -o shard$k.navmesh --areas areas.json --summary shard$k.json --shard $k/3 >/dev/null 2>&1 ||
        fail "shard $k/3 failed"
done
expect_error "the bake had 3 shards, 2 are given" merged.navmesh merge shard0.navmesh shard2.navmesh \
    --summary shard0.json --summary shard2.json -o merged.navmesh
expect_error "different bakes" merged.navmesh merge shard0.navmesh shard1.navmesh shard2.navmesh \
    --summary shard0.json --summary shard2.json --summary shard1.json -o merged.navmesh
"$bake" merge shard0.navmesh shard1.navmesh shard2.navmesh --summary shard0.json --summary shard1.json \
    --summary shard2.json -o merged.navmesh >merge.log 2>&1 || fail "merging every shard failed: $(cat merge.log)"
cmp -s merged.navmesh level.navmesh || fail "the merged shards differ from the one-machine bake"
# Shards leave the links to the merge, which warns of the dead one
for k in 0 1; do
    "$bake" bake level.obj -o dead$k.navmesh --links dead-links.json --shard $k/2 >dead$k.log 2>&1 ||
        fail "dead link shard $k/2 failed"
done
grep -q "off-mesh links: 1, not checked" dead0.log || fail "a shard claimed to check the links: $(cat dead0.log)"
"$bake" merge dead0.navmesh dead1.navmesh --links dead-links.json -o dead-merged.navmesh >merge.log 2>&1 ||
    fail "merging the dead link's shards failed: $(cat merge.log)"
grep -q "warning: off-mesh link (user id 9) .*its end joins no navmesh" merge.log ||
    fail "the merge did not warn of the dead link: $(cat merge.log)"
"$bake" merge shard0.navmesh shard2.navmesh -o merged2.navmesh >merge.log 2>&1 || fail "merge without summaries"
grep -q "a missing shard cannot be noticed" merge.log || fail "merge without summaries did not warn: $(cat merge.log)"

# A failed summary write leaves the previous outputs as they were: a level whose summary is far larger than
# its navmesh (thousands of empty tiles between two small floors), under a file size limit the navmesh fits
cat >sparse.obj <<'OBJ'
v 0 0 0
v 4 0 0
v 4 0 4
v 0 0 4
v 500 0 500
v 504 0 500
v 504 0 504
v 500 0 504
f 1 3 2
f 1 4 3
f 5 7 6
f 5 8 7
OBJ
echo "the previous bake" >sparse.navmesh
(
    ulimit -f 64 # 32 KB
    trap '' XFSZ # An oversized write fails (EFBIG) instead of killing the baker
    "$bake" bake sparse.obj -o sparse.navmesh --summary sparse.json >sparse.log 2>&1
)
code=$?
[ "$code" -eq 1 ] || fail "a bake whose summary could not be written exited with $code: $(cat sparse.log)"
[ "$(cat sparse.navmesh)" = "the previous bake" ] || fail "a failed bake replaced its navmesh"
[ ! -e sparse.json ] || fail "a failed bake left a summary"

# SIGTERM during a bake leaves no temporary file: a level big enough to be interrupted, killed once its
# navmesh's temporary exists
awk 'BEGIN { n = 120; for (z = 0; z <= n; ++z) for (x = 0; x <= n; ++x) printf "v %d %.2f %d\n", x, ((x * 7 + z * 13) % 5) * 0.05, z;
             for (z = 0; z < n; ++z) for (x = 0; x < n; ++x) { a = z * (n + 1) + x + 1; b = a + 1; c = a + n + 1; d = c + 1;
             printf "f %d %d %d\nf %d %d %d\n", a, c, b, b, c, d } }' >terrain.obj
"$bake" bake terrain.obj -o terrain.navmesh --threads 1 --cell-size 0.1 >terrain.log 2>&1 &
baker=$!
for _ in $(seq 200); do
    if ls terrain.navmesh.tmp-* >/dev/null 2>&1; then break; fi
    sleep 0.05
done
ls terrain.navmesh.tmp-* >/dev/null 2>&1 || fail "the terrain bake made no temporary file: $(cat terrain.log)"
kill -TERM "$baker"
wait "$baker"
code=$?
[ "$code" -eq 143 ] || fail "the terrain bake was not ended by SIGTERM (exit $code): $(cat terrain.log)"
[ ! -e terrain.navmesh ] || fail "an interrupted bake left its navmesh"

if ls ./*.tmp* >/dev/null 2>&1; then fail "temporary files left: $(ls ./*.tmp*)"; fi
echo "cairn-bake command line: all checks passed"
