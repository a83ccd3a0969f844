#!/usr/bin/env bash
# Daemon and receiver on two "hosts": two network namespaces joined by a veth
# pair (10.213.0.1 <-> 10.213.0.2, addresses that exist only inside them).
# ictusd runs in one, bound to its own address and allowing only the other;
# oscdump listens in the other. Checks that every strike ictusd recorded
# arrives, and that a command sent across gets its reply.
# Usage: netns_strikes.sh ICTUSD_OSC DATA_DIR. Exit 77 (skipped) when it cannot
# run here: not root, no `ip netns`, or no data (outside CI).
set -u
ictusd=$1
data=$2
clip=$data/cmu/80_13.bvh

skip() {
    echo "SKIPPED: $*"
    exit 77
}
[ "$(id -u)" = 0 ] || skip "needs root for ip netns (running as uid $(id -u))"
command -v ip >/dev/null || skip "no ip command (iproute2)"
command -v oscdump >/dev/null || skip "no oscdump (liblo-tools)"
if [ ! -f "$clip" ]; then
    [ "${CI:-}" = true ] && { echo "FAIL: CI=true and the clip is missing: $clip"; exit 1; }
    skip "the CMU clip is missing: $clip (set ICTUS_DATA_DIR)"
fi

a=ictus-osc-a-$$
b=ictus-osc-b-$$
work=$(mktemp -d)
cleanup() {
    [ -n "${dump_pid:-}" ] && kill "$dump_pid" 2>/dev/null
    ip netns del "$a" 2>/dev/null
    ip netns del "$b" 2>/dev/null
    rm -rf "$work"
}
trap cleanup EXIT

ip netns add "$a" 2>"$work/err" || skip "ip netns add failed: $(cat "$work/err")"
ip netns add "$b" || skip "ip netns add failed"
ip link add "via$$" netns "$a" type veth peer name "vib$$" netns "$b" ||
    skip "cannot create a veth pair"
ip -n "$a" addr add 10.213.0.1/30 dev "via$$"
ip -n "$b" addr add 10.213.0.2/30 dev "vib$$"
for ns in "$a" "$b"; do
    ip -n "$ns" link set lo up
done
ip -n "$a" link set "via$$" up
ip -n "$b" link set "vib$$" up

ip netns exec "$b" oscdump -L 9000 >"$work/dump.txt" 2>&1 &
dump_pid=$!
# oscdump listening before the daemon starts (at most 10 s).
for _ in $(seq 100); do
    [ -n "$(ip netns exec "$b" ss -Hlun 'sport = :9000' 2>/dev/null)" ] && break
    sleep 0.1
done

ip netns exec "$a" "$ictusd" run --mocap "$clip" --autoplay --duration 4 \
    --target osc.udp://10.213.0.2:9000 --bind 10.213.0.1 --allow 10.213.0.2 --port 9001 \
    --reply osc.udp://10.213.0.2:9000 --out "$work/run" &
daemon_pid=$!
# Pings from b until one is answered or the daemon has ended (loading the clip
# and binding may take long under a sanitizer or a loaded machine): a
# handshake, not a fixed number of tries.
while kill -0 "$daemon_pid" 2>/dev/null && ! grep -q ' /ictus/pong' "$work/dump.txt"; do
    ip netns exec "$b" oscsend 10.213.0.1 9001 /ictus/ping
    sleep 0.25
done
wait "$daemon_pid" || {
    echo "FAIL: ictusd run exited with $?"
    exit 1
}
# oscdump may still be printing the last strikes: wait until it has them all
# (at most 10 s).
count=$(($(wc -l <"$work/run/strikes.csv") - 1))
for _ in $(seq 100); do
    [ "$(grep -c ' /ictus/strike ' "$work/dump.txt")" -ge "$count" ] && break
    sleep 0.1
done

recorded=$(tail -n +2 "$work/run/strikes.csv" | cut -d, -f1 | sort -n | tr '\n' ' ')
received=$(awk '$2 == "/ictus/strike" { print $4 }' "$work/dump.txt" | sort -n | tr '\n' ' ')
pongs=$(grep -c ' /ictus/pong' "$work/dump.txt")
frames=$(grep -c ' /ictus/pose/frame' "$work/dump.txt")
echo "recorded strikes: $recorded"
echo "received strikes: $received"
echo "pose frames: $frames, pongs: $pongs"
[ -n "$recorded" ] || { echo "FAIL: no strikes recorded"; exit 1; }
[ "$recorded" = "$received" ] || { echo "FAIL: strikes lost between the namespaces"; exit 1; }
[ "$pongs" -ge 1 ] || { echo "FAIL: no /ictus/pong came back across the namespaces"; exit 1; }
echo "ok: every strike crossed from $a (10.213.0.1) to $b (10.213.0.2)"
