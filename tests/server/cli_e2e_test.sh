#!/usr/bin/env bash
# End-to-end: a real stylus-server process on a free port, driven by the
# `stylus` CLI; then SIGTERM, which must stop it cleanly with exit code 0.
# Usage: cli_e2e_test.sh STYLUS_SERVER STYLUS SOURCE_DIR WORK_DIR
set -u
server=$1 cli=$2 src=$3 work=$4
rm -rf "$work" && mkdir -p "$work"
source "$(dirname "$0")/../check.sh"

check "server --help" 0 "usage: stylus-server" -- "$server" --help
check "server bad option" 2 "unknown option --bogus" -- "$server" --bogus 1
check "server missing models" 1 "does not exist" -- "$server" --models "$work/none" --listen localhost:0
check "cli --help" 0 "usage: stylus" -- "$cli" --help
check "cli no server" 1 "UNAVAILABLE" -- "$cli" --server localhost:1 --deadline-s 2 models
check "no server names the address and the fix" 1 "did not get through to a serving Stylus server at localhost:1: .*--server HOST:PORT or STYLUS_SERVER" -- \
  "$cli" --server localhost:1 --deadline-s 2 models

"$server" --models "$src/models" --listen localhost:0 --port-file "$work/port" >"$work/server.log" 2>&1 &
pid=$!
for _ in $(seq 1 300); do [ -s "$work/port" ] && break; sleep 0.1; done
if [ ! -s "$work/port" ]; then
  echo "FAIL: the server did not start:"; cat "$work/server.log"; kill "$pid"; exit 1
fi
addr=localhost:$(cat "$work/port")
s=(--server "$addr")
walk=$src/samples/walk_normal.bvh old=$src/samples/walk_old.bvh run=$src/samples/run.bvh
default=$(grep -v '^#' "$src/models/DEFAULT")  # the package the server serves by default

check "health" 0 "^SERVING" -- "$cli" "${s[@]}" health
check "a dns:/// target" 0 "$default" -- "$cli" --server "dns:///$addr" models
check "models" 0 "$default \(default\)" -- "$cli" "${s[@]}" models
check "models lists both families" 0 "cyclic/v2" -- "$cli" "${s[@]}" models
check "model-info" 0 "window 32" -- "$cli" "${s[@]}" model-info --model contrastive
check "model-info cyclic" 0 "window 60" -- "$cli" "${s[@]}" model-info --model cyclic
check "a content guard's note says what it did" 0 "content guard: the transfer as configured read as another action than the content's; returned instead: the content plus [0-9.]+ x the change the style makes" -- \
  "$cli" "${s[@]}" transfer --model cyclic --content "$walk" --style "$old" -o "$work/guarded.bvh"
check "transfer --model cyclic" 0 "wrote .*cyc.bvh \(120 frames\)" -- "$cli" "${s[@]}" transfer --model cyclic \
  --content "$walk" --style "$old" -o "$work/cyc.bvh"
check "stream --model cyclic" 0 "streamed 120 frames .*got 120 back" -- "$cli" "${s[@]}" stream --model cyclic \
  --content "$walk" --style "$old" -o "$work/cyc_stream.bvh"
check "model-info live" 0 "live, lookahead 2" -- "$cli" "${s[@]}" model-info --model live
check "stream --model live with style changes" 0 "streamed 120 frames .*got 120 back" -- "$cli" "${s[@]}" \
  stream --model live --content "$walk" --style "$old" --change "30:$run:10" --change 60:strength=0.5:5 \
  -o "$work/live_stream.bvh"
check "stream --change on an offline model" 1 "FAILED_PRECONDITION.*live model" -- "$cli" "${s[@]}" \
  stream --content "$walk" --style "$old" --change 30:strength=0.5
check "stream --change malformed" 1 "--change 30: expected FRAME:WHAT" -- "$cli" "${s[@]}" \
  stream --model live --content "$walk" --style "$old" --change 30
check "model-info unknown" 1 "NOT_FOUND" -- "$cli" "${s[@]}" model-info --model nope/v1
check "unload the default" 1 "FAILED_PRECONDITION: $default is the default model" -- "$cli" "${s[@]}" unload --model $default
check "unload" 0 "unloaded cyclic/v1" -- "$cli" "${s[@]}" unload --model cyclic/v1
check "transfer on an unloaded model" 1 "NOT_FOUND" -- "$cli" "${s[@]}" transfer --model cyclic/v1 --content "$walk" --style "$old" -o "$work/x.bvh"
check "load" 0 "loaded cyclic/v1" -- "$cli" "${s[@]}" load --model cyclic/v1
check "load twice" 1 "ALREADY_EXISTS" -- "$cli" "${s[@]}" load --model cyclic/v1
check "transfer --postprocess none" 0 "wrote" -- "$cli" "${s[@]}" transfer --postprocess none --content "$walk" --style "$old" -o "$work/raw.bvh"
check "transfer" 0 "wrote .*out.bvh \(120 frames\)" -- "$cli" "${s[@]}" transfer --content "$walk" --style "$old" -o "$work/out.bvh"
check "transfer output is BVH" 0 "HIERARCHY" -- head -1 "$work/out.bvh"
check "transfer --timing style" 0 "wrote .*timed.bvh \([0-9]+ frames\) .*\(played [0-9.]+x as long\)" -- \
  "$cli" "${s[@]}" transfer --content "$walk" --style "$old" --timing style -o "$work/timed.bvh"
check "transfer --fit-frames" 0 "wrote .*fitted.bvh \(150 frames\) .*\(played [0-9.]+x as long\) \(movement: " -- \
  "$cli" "${s[@]}" transfer --content "$walk" --style "$old" --fit-frames 150 -o "$work/fitted.bvh"
check "transfer --fit-frames out of range" 1 "fit_frames 1000 is not within 0.5-2x" -- \
  "$cli" "${s[@]}" transfer --content "$walk" --style "$old" --fit-frames 1000 -o "$work/fitted.bvh"
check "transfer --timing bad" 1 "--timing must be content or style" -- "$cli" "${s[@]}" transfer \
  --content "$walk" --style "$old" --timing beat -o "$work/x.bvh"
check "transfer --model" 0 "wrote" -- "$cli" "${s[@]}" transfer --model $default --content "$walk" --style "$old" -o "$work/out2.bvh"
check "interpolate" 0 "wrote .*mix_2.bvh \(weights 0:1\)" -- "$cli" "${s[@]}" interpolate --content "$walk" --style "$old" --style "$run" --weights 0,0.5,1 -o "$work/mix"
check "interpolate files" 0 "mix_0.bvh" -- ls "$work/mix_0.bvh" "$work/mix_1.bvh" "$work/mix_2.bvh"
check "stream" 0 "streamed 120 frames at 60.0 fps; got 120 back; latency p50 [0-9.]+ ms, p99 [0-9.]+ ms" -- "$cli" "${s[@]}" stream --content "$walk" --style "$old" --rate 60 -o "$work/stream.bvh"
check "metrics" 0 '^\{"bone_length_error": .*"foot_skating": .*"trajectory_error": ' -- "$cli" "${s[@]}" metrics --output "$work/out.bvh" --content "$walk" --style "$old"
check "encode-style --save-as" 0 "144 values; saved as 'old'" -- "$cli" "${s[@]}" encode-style --style "$old" --save-as old
check "model-info lists saved styles" 0 "saved_styles old" -- "$cli" "${s[@]}" model-info
check "transfer --style-name" 0 "wrote" -- "$cli" "${s[@]}" transfer --content "$walk" --style-name old -o "$work/named.bvh"
check "interpolate a saved name with a clip" 0 "wrote .*named_mix_0.bvh \(weights 0.7:0.3\)" -- "$cli" "${s[@]}" interpolate \
  --content "$walk" --style old --style "$run" --weights 0.3 -o "$work/named_mix"
check "stream --style-name" 0 "streamed 120 frames .*got 120 back" -- "$cli" "${s[@]}" stream --content "$walk" \
  --style-name old --rate 0
check "convert a BVH to glTF (no server)" 0 "wrote .*walk.glb: 22 joints, 120 frames" -- \
  "$cli" --server localhost:1 convert --in "$walk" -o "$work/walk.glb"
check "convert the glTF back" 0 "wrote .*walk_back.bvh: 22 joints, 120 frames" -- \
  "$cli" convert --in "$work/walk.glb" -o "$work/walk_back.bvh"
check "transfer a glTF content into a glTF" 0 "wrote .*walk_old.glb \(120 frames\)" -- \
  "$cli" "${s[@]}" transfer --content "$work/walk.glb" --style "$old" -o "$work/walk_old.glb"
check "the restyled glTF reads back" 0 "wrote .*walk_old_back.bvh: 22 joints, 120 frames" -- \
  "$cli" convert --in "$work/walk_old.glb" -o "$work/walk_old_back.bvh"
check "an FBX output is refused before the call" 1 "-o $work/x.fbx: stylus writes a .bvh, .gltf or .glb file" -- \
  "$cli" "${s[@]}" transfer --content "$walk" --style "$old" -o "$work/x.fbx"
check "an unknown clip type names the ones read" 1 "clip.txt: unknown file type; Stylus reads a .bvh, .fbx, .gltf, .glb or .dae file" -- \
  "$cli" "${s[@]}" transfer --content "$work/clip.txt" --style "$old" -o "$work/x.bvh"
check "interpolate writes glTF by the prefix's extension" 0 "wrote .*mix_glb_0.glb" -- \
  "$cli" "${s[@]}" interpolate --content "$walk" --style "$old" --style "$run" --weights 0.5 -o "$work/mix_glb.glb"
printf '# the walk turns old, then runs\n0 1 0 0\n40 0 1 0\n100 0 0 1\n' > "$work/schedule.txt"
check "interpolate --schedule" 0 "wrote .*scheduled.bvh \(weights per frame from .*schedule.txt\)" -- \
  "$cli" "${s[@]}" interpolate --content "$walk" --style "$walk" --style "$old" --style "$run" \
  --schedule "$work/schedule.txt" -o "$work/scheduled"
printf '0 1 0\n' > "$work/bad_schedule.txt"
check "a schedule with too few weights names its line" 1 "bad_schedule.txt:1: 2 weights for 3 styles" -- \
  "$cli" "${s[@]}" interpolate --content "$walk" --style "$walk" --style "$old" --style "$run" \
  --schedule "$work/bad_schedule.txt" -o "$work/x"
check "a missing output folder is refused before the call" 1 "-o $work/no_such_dir/x.bvh: the folder $work/no_such_dir does not exist" -- \
  "$cli" "${s[@]}" transfer --content "$walk" --style "$old" -o "$work/no_such_dir/x.bvh"
check "... and for interpolate" 1 "the folder $work/no_such_dir does not exist" -- \
  "$cli" "${s[@]}" interpolate --content "$walk" --style "$old" --style "$run" --weights 0.5 -o "$work/no_such_dir/m"
check "... and for stream" 1 "the folder $work/no_such_dir does not exist" -- \
  "$cli" "${s[@]}" stream --content "$walk" --style "$old" -o "$work/no_such_dir/x.bvh"
check "a stream sent at another rate than the clip's says so" 0 "recorded at 30 fps and is sent at 60 fps: it plays 2.00x faster" -- \
  "$cli" "${s[@]}" stream --content "$walk" --style "$old" --rate 60
check "unknown style name" 1 "NOT_FOUND: .*'young'" -- "$cli" "${s[@]}" transfer --content "$walk" --style-name young -o "$work/x.bvh"
check "unknown model" 1 "NOT_FOUND: unknown model 'cyclic/v9'" -- "$cli" "${s[@]}" transfer --model cyclic/v9 --content "$walk" --style "$old" -o "$work/x.bvh"
check "a rig that is no humanoid" 1 "INVALID_ARGUMENT: content clip is on another rig than the model's: not a humanoid rig" -- "$cli" "${s[@]}" transfer --content "$src/tests/fixtures/bvh/good/three_joint.bvh" --style "$old" -o "$work/x.bvh"
rigs=$src/../shared/data/rigs
if [ -d "$rigs" ]; then
  printf 'left_foot = LeftAnkle\nright_foot = RightAnkle\n' > "$work/map.txt"
  check "transfer on another rig with --joint-map" 0 "wrote .*mocap.bvh \(455 frames\)" -- "$cli" "${s[@]}" \
    transfer --content "$rigs/mocapbank_19joints_30fps.bvh" --style "$old" --joint-map "$work/map.txt" -o "$work/mocap.bvh"
  check "stream on another rig" 0 "got 69 back" -- "$cli" "${s[@]}" stream --model live \
    --content "$rigs/mixamo_55joints_30fps.bvh" --style "$old" -o "$work/mixamo_stream.bvh"
  printf 'left_foot = Nope\n' > "$work/badmap.txt"
  check "a joint map naming a missing joint" 1 "INVALID_ARGUMENT: .*left_foot = 'Nope'" -- "$cli" "${s[@]}" \
    transfer --content "$rigs/mocapbank_19joints_30fps.bvh" --style "$old" --joint-map "$work/badmap.txt" -o "$work/x.bvh"
elif [ "${CI:-}" = true ]; then
  echo "FAIL: $rigs missing (required under CI)"; failed=$((failed + 1))
fi
check "a joint map that is not a file" 1 "cannot open the joint map" -- "$cli" "${s[@]}" \
  transfer --content "$walk" --style "$old" --joint-map "$work/none.txt" -o "$work/x.bvh"
check "bad BVH" 1 "nan_value.bvh:25" -- "$cli" "${s[@]}" transfer --content "$src/tests/fixtures/bvh/bad/nan_value.bvh" --style "$old" -o "$work/x.bvh"
check "missing -o" 1 "-o is required" -- "$cli" "${s[@]}" transfer --content "$walk" --style "$old"
check "bad weights" 1 "'x' is not a number" -- "$cli" "${s[@]}" interpolate --content "$walk" --style "$old" --style "$run" --weights 0,x -o "$work/m"
check "bad postprocess" 1 "--postprocess must be" -- "$cli" "${s[@]}" transfer --postprocess wobbly --content "$walk" --style "$old" -o "$work/x.bvh"
check "unknown command" 2 "unknown command 'frobnicate'" -- "$cli" "${s[@]}" frobnicate
check "a command's --help lists its own options" 0 "usage: stylus stream --content C.bvh \(--style S.bvh \| --style-name NAME\) \[--rate FPS\]" -- \
  "$cli" stream --help
check "a command's --help names the call options" 0 "--postprocess default\|none\|feet\|full" -- "$cli" transfer --help
check "a command refuses another command's options" 2 "unknown option --weights" -- \
  "$cli" "${s[@]}" transfer --content "$walk" --style "$old" --weights 0,1 -o "$work/x.bvh"
check "models takes no --content" 2 "unknown option --content" -- "$cli" "${s[@]}" models --content "$walk"
check "global options after the command" 0 "$default \(default\)" -- "$cli" models "${s[@]}" --deadline-s 30
check "STYLUS_SERVER sets the address" 0 "$default \(default\)" -- env STYLUS_SERVER="$addr" "$cli" models
check "--server wins over STYLUS_SERVER" 1 "UNAVAILABLE" -- env STYLUS_SERVER="$addr" "$cli" models \
  --server localhost:1 --deadline-s 2
check "server logs one line per call" 0 "rpc=Transfer model=$default frames=120 ms=[0-9.]+ status=OK guard=(configured|residual:[0-9.]+) " -- cat "$work/server.log"

kill -TERM "$pid"
wait "$pid"
rc=$?
if [ "$rc" -eq 0 ] && grep -q "shut down" "$work/server.log"; then
  passed=$((passed + 1))
else
  failed=$((failed + 1)); echo "FAIL SIGTERM: exit $rc"; tail -5 "$work/server.log"
fi
# A server that wants a token: the CLI's --token and $STYLUS_TOKEN, SIGHUP
# re-reading the file, and no token in its log.
printf '# tokens\ns3cret-alpha\n' >"$work/tokens"
rm -f "$work/port"
"$server" --models "$src/models" --listen localhost:0 --port-file "$work/port" \
  --auth-tokens "$work/tokens" >"$work/auth.log" 2>&1 &
pid=$!
for _ in $(seq 1 300); do [ -s "$work/port" ] && break; sleep 0.1; done
a=(--server "localhost:$(cat "$work/port")")
check "health needs no token" 0 "^SERVING" -- "$cli" "${a[@]}" health
check "no token" 1 "UNAUTHENTICATED.*Bearer" -- "$cli" "${a[@]}" models
check "a wrong token" 1 "UNAUTHENTICATED" -- "$cli" "${a[@]}" --token s3cret-beta models
check "--token" 0 "$default \(default\)" -- "$cli" "${a[@]}" --token s3cret-alpha models
check "STYLUS_TOKEN" 0 "$default" -- env STYLUS_TOKEN=s3cret-alpha "$cli" "${a[@]}" models
printf 's3cret-beta\n' >"$work/tokens"
kill -HUP "$pid"
for _ in $(seq 1 50); do grep -q "SIGHUP" "$work/auth.log" && break; sleep 0.1; done
check "SIGHUP re-reads the tokens" 0 "1 token\(s\) in force" -- cat "$work/auth.log"
check "an old token after SIGHUP" 1 "UNAUTHENTICATED" -- "$cli" "${a[@]}" --token s3cret-alpha models
check "the new token after SIGHUP" 0 "$default" -- "$cli" "${a[@]}" --token s3cret-beta models
check "the log says access is by token" 0 "access: bearer tokens from" -- cat "$work/auth.log"
check "no token in the log" 1 "^0$" -- grep -c s3cret "$work/auth.log"
kill -TERM "$pid"
wait "$pid"
check "the token server stops on SIGTERM" 0 "shut down" -- cat "$work/auth.log"

# TLS with a client certificate (mutual TLS), from certificates made here.
"$(dirname "$0")/make_test_certs.sh" "$work/pki" >"$work/pki.log" 2>&1 || { echo "FAIL: openssl"; cat "$work/pki.log"; exit 1; }
p=$work/pki
check "server TLS key without a cert" 1 "needs both --tls-cert and --tls-key" -- \
  "$server" --models "$src/models" --listen localhost:0 --tls-key "$p/server.key"
rm -f "$work/port"
"$server" --models "$src/models" --listen localhost:0 --port-file "$work/port" \
  --tls-cert "$p/server.pem" --tls-key "$p/server.key" --tls-client-ca "$p/ca.pem" \
  --log-format json >"$work/tls.log" 2>&1 &
pid=$!
for _ in $(seq 1 300); do [ -s "$work/port" ] && break; sleep 0.1; done
t=(--server "localhost:$(cat "$work/port")" --deadline-s 10)
mtls=(--tls-ca "$p/ca.pem" --tls-cert "$p/client.pem" --tls-key "$p/client.key")
check "the log says TLS" 0 "transport: TLS .*client certificates required" -- cat "$work/tls.log"
check "plain text to a TLS server" 1 "UNAVAILABLE" -- "$cli" "${t[@]}" models
check "TLS without a client cert" 1 "UNAVAILABLE" -- "$cli" "${t[@]}" --tls-ca "$p/ca.pem" models
check "mutual TLS" 0 "$default \(default\)" -- "$cli" "${t[@]}" "${mtls[@]}" models
check "mutual TLS transfer" 0 "wrote .*tls.bvh" -- "$cli" "${t[@]}" "${mtls[@]}" transfer \
  --content "$walk" --style "$old" -o "$work/tls.bvh"
check "STYLUS_TLS_CA" 0 "$default" -- env STYLUS_TLS_CA="$p/ca.pem" "$cli" "${t[@]}" \
  --tls-cert "$p/client.pem" --tls-key "$p/client.key" models
check "a cert without its key" 2 "needs its key" -- "$cli" "${t[@]}" --tls-cert "$p/client.pem" models
check "a CA that is not PEM" 2 "is not a PEM certificate" -- "$cli" "${t[@]}" --tls-ca "$p/client.key" models
kill -TERM "$pid"
wait "$pid"
check "the TLS server stops on SIGTERM" 0 "shut down" -- cat "$work/tls.log"
# --log-format json: every line is one JSON object; calls carry a request id and the peer.
check "JSON logs parse" 0 "calls [3-9]" -- /usr/bin/python3 -c '
import json, sys
lines = [json.loads(l) for l in open(sys.argv[1])]
calls = [l for l in lines if "rpc" in l]
assert len(calls) >= 3 and all(l["request_id"] and l["peer"] for l in calls), calls
print("lines", len(lines), "calls", len(calls))' "$work/tls.log"
check "server --log-format bad" 2 "unknown log format" -- "$server" --log-format xml
check "the plain server said plain text" 0 "transport: plain text" -- cat "$work/server.log"

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
