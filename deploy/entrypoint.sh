#!/bin/sh
# The image's entrypoint: stylus-server with flags from the environment
# (each unset or empty variable leaves the server's default), then any
# arguments given to the container.
#   STYLUS_LISTEN          default 0.0.0.0:50051
#   STYLUS_MODELS          default /opt/stylus/models (mount your own over it)
#   STYLUS_DEFAULT_MODEL   e.g. contrastive/v10
#   STYLUS_THREADS         compute threads
#   STYLUS_METRICS_LISTEN  e.g. 0.0.0.0:9464
#   STYLUS_TLS_CERT, STYLUS_TLS_KEY, STYLUS_TLS_CLIENT_CA   PEM files
#   STYLUS_AUTH_TOKENS     tokens file (re-read when it changes)
#   STYLUS_ADMIN_TOKENS    admin tokens file (LoadModel/UnloadModel)
#   STYLUS_MAX_MEMORY_MB, STYLUS_MAX_MESSAGE_MB   memory bounds
#   STYLUS_LOG_FORMAT      text or json (default json in the image)
#   STYLUS_SHUTDOWN_GRACE_S
set -eu
set -- --listen "${STYLUS_LISTEN:-0.0.0.0:50051}" --models "${STYLUS_MODELS:-/opt/stylus/models}" \
  --log-format "${STYLUS_LOG_FORMAT:-json}" "$@"
add() {  # FLAG VALUE: adds the flag when VALUE is not empty.
  if [ -n "$2" ]; then extra="$extra $1 $2"; fi
}
extra=""
add --default-model "${STYLUS_DEFAULT_MODEL:-}"
add --threads "${STYLUS_THREADS:-}"
add --metrics-listen "${STYLUS_METRICS_LISTEN:-}"
add --tls-cert "${STYLUS_TLS_CERT:-}"
add --tls-key "${STYLUS_TLS_KEY:-}"
add --tls-client-ca "${STYLUS_TLS_CLIENT_CA:-}"
add --auth-tokens "${STYLUS_AUTH_TOKENS:-}"
add --admin-tokens "${STYLUS_ADMIN_TOKENS:-}"
add --max-memory-mb "${STYLUS_MAX_MEMORY_MB:-}"
add --max-message-mb "${STYLUS_MAX_MESSAGE_MB:-}"
add --shutdown-grace-s "${STYLUS_SHUTDOWN_GRACE_S:-}"
# The values are paths, addresses and numbers: word splitting is safe.
# shellcheck disable=SC2086
exec /usr/local/bin/stylus-server $extra "$@"
