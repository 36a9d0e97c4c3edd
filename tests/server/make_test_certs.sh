#!/usr/bin/env bash
# A throw-away PKI for the TLS tests, made with Debian's openssl:
#   ca.pem                   the CA the server and clients trust
#   server.pem, server.key   signed by it, for localhost and 127.0.0.1
#   client.pem, client.key   signed by it, for client authentication
#   other_ca.pem             a CA nobody trusts...
#   other_client.pem/.key    ...and a client certificate it signed
#   other_server.pem/.key    a server certificate it signed (a renewed one)
# Usage: make_test_certs.sh DIR   (valid for two days)
set -euo pipefail
dir=${1:?usage: make_test_certs.sh DIR}
mkdir -p "$dir"
cd "$dir"

key() { openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:P-256 -out "$1" 2>/dev/null; }
ca() {  # NAME CN
  key "$1.key"
  openssl req -x509 -new -key "$1.key" -out "$1.pem" -days 2 -subj "/CN=$2"
}
leaf() {  # NAME CN CA EXTENSIONS
  key "$1.key"
  openssl req -new -key "$1.key" -out "$1.csr" -subj "/CN=$2"
  printf '%s\n' "$4" > "$1.ext"
  openssl x509 -req -in "$1.csr" -CA "$3.pem" -CAkey "$3.key" -CAcreateserial -days 2 \
    -extfile "$1.ext" -out "$1.pem" 2>/dev/null
}

ca ca "Stylus test CA"
leaf server localhost ca "subjectAltName=DNS:localhost,IP:127.0.0.1
extendedKeyUsage=serverAuth"
leaf client "stylus test client" ca "extendedKeyUsage=clientAuth"
ca other_ca "Untrusted test CA"
leaf other_client "untrusted client" other_ca "extendedKeyUsage=clientAuth"
leaf other_server localhost other_ca "subjectAltName=DNS:localhost,IP:127.0.0.1
extendedKeyUsage=serverAuth"
rm -f ./*.csr ./*.ext ./*.srl
