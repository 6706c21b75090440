#!/usr/bin/env bash
# End to end as a user would do it: start remeshd, submit a mesh with curl, follow the events with
# curl -N, download OBJ and GLB of the remeshed mesh and the dual, and check the files parse.
# usage: e2e_curl.sh <remeshd> [<dir with the remesh CLI>]     exit 77 = skipped (no curl)
set -euo pipefail
REMESHD=$1
BIN=${2:-}
command -v curl >/dev/null || { echo "curl missing: skipped"; exit 77; }
command -v python3 >/dev/null || { echo "python3 missing: skipped"; exit 77; }

TMP=$(mktemp -d)
PID=
cleanup() { [ -n "$PID" ] && kill "$PID" 2>/dev/null; wait 2>/dev/null || true; rm -rf "$TMP"; }
trap cleanup EXIT

"$REMESHD" --port 0 --data-dir "$TMP/data" --workers 1 2>"$TMP/log" &
PID=$!
for _ in $(seq 200); do grep -q ' port=' "$TMP/log" 2>/dev/null && break; sleep 0.05; done
PORT=$(sed -n 's/.*listening.* port=\([0-9]*\).*/\1/p' "$TMP/log" | head -1)
[ -n "$PORT" ] || { cat "$TMP/log"; echo "remeshd did not start"; exit 1; }
BASE="http://127.0.0.1:$PORT"

# An octahedron subdivided by python (no test data needed): a closed genus-0 OBJ.
python3 - "$TMP/ball.obj" <<'PY'
import sys, math
v = [(1,0,0),(-1,0,0),(0,1,0),(0,-1,0),(0,0,1),(0,0,-1)]
f = [(0,2,4),(2,1,4),(1,3,4),(3,0,4),(2,0,5),(1,2,5),(3,1,5),(0,3,5)]
for _ in range(3):
    cache = {}; nf = []
    def mid(a, b):
        k = (min(a,b), max(a,b))
        if k not in cache:
            p = [(v[a][i]+v[b][i])/2 for i in range(3)]; n = math.sqrt(sum(c*c for c in p))
            v.append(tuple(c/n for c in p)); cache[k] = len(v)-1
        return cache[k]
    for a,b,c in f:
        ab, bc, ca = mid(a,b), mid(b,c), mid(c,a)
        nf += [(a,ab,ca),(b,bc,ab),(c,ca,bc),(ab,bc,ca)]
    f = nf
with open(sys.argv[1], "w") as o:
    for p in v: o.write("v %.9f %.9f %.9f\n" % p)
    for t in f: o.write("f %d %d %d\n" % tuple(i+1 for i in t))
PY

# Submit (raw body, parameters in the query string).
curl -sS -f -o "$TMP/job.json" --data-binary @"$TMP/ball.obj" -H 'Content-Type: model/obj' \
  "$BASE/api/v1/jobs?emin=0.1&emax=0.16&iterations=5&filename=ball.obj"
ID=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["id"])' "$TMP/job.json")
echo "job $ID"

# Follow the events to the end.
timeout 60 curl -sS -N "$BASE/api/v1/jobs/$ID/events" > "$TMP/events.txt"
grep -q '^event: end' "$TMP/events.txt" || { cat "$TMP/events.txt"; echo "no end event"; exit 1; }
grep -q '^data: {"state":"succeeded"}' "$TMP/events.txt" || { cat "$TMP/events.txt"; echo "not succeeded"; exit 1; }
ROWS=$(grep -c '^event: iteration' "$TMP/events.txt")
[ "$ROWS" -ge 1 ] || { echo "no iteration events"; exit 1; }
echo "events: $ROWS iterations"

# Download and check the files parse.
for mesh in remeshed dual; do
  for fmt in obj glb; do
    curl -sS -f -o "$TMP/$mesh.$fmt" -D "$TMP/$mesh.$fmt.headers" "$BASE/api/v1/jobs/$ID/result?mesh=$mesh&format=$fmt"
    grep -qi "content-disposition: attachment; filename=\"ball-$mesh.$fmt\"" "$TMP/$mesh.$fmt.headers" \
      || { cat "$TMP/$mesh.$fmt.headers"; echo "bad Content-Disposition"; exit 1; }
  done
done
python3 - "$TMP" <<'PY'
import json, struct, sys
d = sys.argv[1]
for mesh in ("remeshed", "dual"):
    nv = nf = 0
    for line in open(f"{d}/{mesh}.obj"):
        if line.startswith("v "):
            assert len(line.split()) == 4, line; nv += 1
        elif line.startswith("f "):
            idx = [int(t.split("/")[0]) for t in line.split()[1:]]
            assert len(idx) >= 3 and all(1 <= i <= nv for i in idx), line; nf += 1
    assert nv > 0 and nf > 0, (mesh, nv, nf)
    if mesh == "dual":
        pass
    b = open(f"{d}/{mesh}.glb", "rb").read()
    magic, version, length = struct.unpack_from("<4sII", b, 0)
    assert magic == b"glTF" and version == 2 and length == len(b), (mesh, magic, version, length, len(b))
    clen, ctype = struct.unpack_from("<II", b, 12)
    assert ctype == 0x4E4F534A
    gltf = json.loads(b[20:20 + clen])
    assert gltf["meshes"] and gltf["accessors"], mesh
    print(f"{mesh}: obj {nv} vertices {nf} faces, glb {len(b)} bytes, {len(gltf['accessors'])} accessors")
PY
if [ -n "$BIN" ] && [ -x "$BIN/remesh" ]; then
  "$BIN/remesh" info "$TMP/remeshed.obj" >/dev/null
  "$BIN/remesh" info "$TMP/remeshed.glb" >/dev/null
  echo "remesh info reads the downloads"
fi
curl -sS -f "$BASE/healthz" | grep -q '"status":"ok"'
echo "e2e ok"
