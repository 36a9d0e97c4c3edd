#!/usr/bin/env bash
# The architecture's include rules (docs/layout.md), checked on the sources:
#   no LibTorch in server/, client/, wire/, cli/ or motion/;
#   no gRPC in model/, train/, eval/ or motion/;
#   model/ (inference) includes nothing from train/, eval/ or tool/;
#   server/ includes nothing from train/, eval/, tool/ or client/;
#   no model family's folder is named by the server, the client or the benchmarks.
# Usage: layering_test.sh SOURCE_DIR
set -u
src=${1:?source dir}
cd "$src" || exit 2
failures=0
rule() {  # rule DESCRIPTION PATTERN FOLDER...
  local what=$1 pattern=$2
  shift 2
  local hits
  hits=$(grep -rnE "$pattern" --include='*.h' --include='*.cc' "$@" 2>/dev/null)
  if [ -n "$hits" ]; then
    echo "FAIL: $what"
    echo "$hits" | sed 's/^/  /'
    failures=$((failures + 1))
  else
    echo "ok: $what"
  fi
}
rule "no LibTorch outside model/, train/, eval/" '#include <(torch|ATen|c10)/' \
  server client wire cli motion tool
rule "no gRPC in model/, train/, eval/, motion/" '#include <grpc' model train eval motion
rule "model/ includes no training, evaluation or tool code" '#include "(train|eval|tool|server|client)/' model
rule "train/ includes no evaluation, tool or server code" '#include "(eval|tool|server|client)/' train
rule "server/ includes no training, evaluation, tool or client code" \
  '#include "(train|eval|tool|client)/' server
rule "client/ and wire/ include no model, server or tool code" \
  '#include "(model|train|eval|server|tool)/' client wire
rule "no family is named outside its folder" '#include "model/(contrastive|cyclic)/' \
  server client wire bench/server_bench.cc bench/transfer_bench.cc
rule "file formats (assimp) only in formats/" '#include <assimp/' \
  server client wire cli motion model train eval tool
rule "server/, wire/ and model/ read no file formats" '#include "formats/' server wire model
rule "OSC (liblo) only in bridge/" '#include <lo/' server client wire cli motion model train eval tool formats
echo "layering: $((10 - failures)) passed, $failures failed"
[ "$failures" -eq 0 ]
