#!/usr/bin/env bash
# Checks the guide's mutual-TLS recipe (docs/guide.md) for zenoh workers end to end (not part of CI: the TLS
# build adds rustls and about four minutes). Builds with `--features zenoh-tls`, makes a
# throwaway CA with a coordinator and a worker certificate, then:
#   1. a worker holding a certificate of that CA joins a small fit over tls/ and the fit ends;
#   2. a worker with a self-signed certificate is not admitted;
#   3. a worker trying plain tcp/ on the TLS port is not admitted.
# Needs openssl. Exits non-zero on the first surprise.
set -euo pipefail
cd "$(dirname "$0")/.."
command -v openssl >/dev/null || { echo "tls-check: openssl is needed" >&2; exit 2; }
cargo build --release --workspace --features zenoh-tls
bin="${CARGO_TARGET_DIR:-$PWD/target}/release"
dir=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$dir"' EXIT
cd "$dir"
port=${PORT:-7491}

openssl req -x509 -newkey rsa:2048 -nodes -keyout ca-key.pem -out ca.pem -days 1 \
    -subj "/CN=sepval tls-check CA" 2>/dev/null
for n in coord worker; do
    openssl req -newkey rsa:2048 -nodes -keyout "$n-key.pem" -out "$n.csr" -subj "/CN=localhost" 2>/dev/null
    printf 'subjectAltName=DNS:localhost,IP:127.0.0.1\n' >"$n.ext"
    openssl x509 -req -in "$n.csr" -CA ca.pem -CAkey ca-key.pem -CAcreateserial -out "$n.pem" \
        -days 1 -extfile "$n.ext" 2>/dev/null
done
openssl req -x509 -newkey rsa:2048 -nodes -keyout rogue-key.pem -out rogue.pem -days 1 \
    -subj "/CN=localhost" -addext "subjectAltName=DNS:localhost" 2>/dev/null
tls() { # side key cert
    printf '{ transport: { link: { tls: { root_ca_certificate: "ca.pem", enable_mtls: true,\n'
    printf '  %s_private_key: "%s", %s_certificate: "%s" } } } }\n' "$1" "$2" "$1" "$3"
}
tls listen coord-key.pem coord.pem >coordinator.json5
tls connect worker-key.pem worker.pem >worker.json5
tls connect rogue-key.pem rogue.pem >rogue.json5

fit() { # run-id join-timeout port
    "$bin/sepval" fit --method ga --generations 3 --population 20 --no-figures \
        --evaluator zenoh --listen "tls/localhost:$3" --zenoh-config coordinator.json5 \
        --run-id "$1" --join-timeout "$2" --out "out-$1" >"fit-$1.log" 2>&1
}
refused() { # run-id port worker-args...
    local run=$1 at=$2
    shift 2
    fit "$run" 6 "$at" &
    local coord=$!
    if timeout 30 "$bin/sepval-worker" --run "$run" --setup-timeout 3 "$@" 2>"worker-$run.log"; then
        echo "tls-check: FAILED: a worker with $* was admitted" >&2
        exit 1
    fi
    if wait "$coord" || ! grep -q "0 of 1 worker(s) joined run $run" "fit-$run.log"; then
        echo "tls-check: FAILED: the fit of run $run did not end for want of a worker:" >&2
        cat "fit-$run.log" >&2
        exit 1
    fi
    echo "tls-check: ok: a worker with $* was not admitted"
}

fit good 30 "$port" &
coord=$!
timeout 60 "$bin/sepval-worker" --connect "tls/localhost:$port" --run good \
    --zenoh-config worker.json5 2>worker-good.log
wait "$coord" || { echo "tls-check: FAILED: the mTLS fit failed:" >&2; cat fit-good.log >&2; exit 1; }
grep -q "results in" fit-good.log
echo "tls-check: ok: a worker with a certificate of the CA joined and the fit ended"

refused rogue $((port + 1)) --connect "tls/localhost:$((port + 1))" --zenoh-config rogue.json5
refused plain $((port + 2)) --connect "tcp/localhost:$((port + 2))"
echo "tls-check: all checks passed"
