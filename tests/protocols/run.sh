#!/usr/bin/env bash
# Alba's protocol servers against clients written elsewhere (called by test.sh):
# pymodbus and a libmodbus C client against `alba run --modbus`, asyncua against
# `alba run --opcua` (and its security: tests/protocols/opcua_security.py); `alba run` as an
# OPC UA client ([[opcua_server]]) against asyncua's server; a pymodbus slave
# polled by `alba run --io modbus`; paho-mqtt, pysparkplug and Mosquitto with `alba run --mqtt` (JSON and Sparkplug B).
# Installs what it needs: Debian's libmodbus-dev and mosquitto, and the PyPI packages of
# requirements.txt in a virtual environment under target/.
set -euo pipefail
cd "$(dirname "$0")/../.."
source scripts/common.sh
ALBA="${1:?usage: tests/protocols/run.sh ALBA_BINARY}"
OUT=target/protocols
mkdir -p "$OUT"
need_pyvenv "$OUT/venv" tests/protocols/requirements.txt
if ! pkg-config --exists libmodbus 2>/dev/null; then
    apt_install libmodbus-dev pkg-config
fi
command -v mosquitto >/dev/null 2>&1 || command -v /usr/sbin/mosquitto >/dev/null 2>&1 || apt_install mosquitto
command -v openssl >/dev/null 2>&1 || apt_install openssl
export PATH="$PATH:/usr/sbin"
cc -O2 -Wall -Wextra -Werror -o "$OUT/libmodbus_smoke" tests/protocols/libmodbus_smoke.c \
    $(pkg-config --cflags --libs libmodbus)
# A fresh copy of the fixture project (alba run keeps retentive data in it).
rm -rf "$OUT/plant"
cp -r tests/protocols/plant "$OUT/plant"
"$OUT/venv/bin/python" tests/protocols/modbus_clients.py "$ALBA" "$OUT/plant" "$OUT/libmodbus_smoke"
# The OPC UA server against asyncua (a fresh copy again).
rm -rf "$OUT/plant"
cp -r tests/protocols/plant "$OUT/plant"
"$OUT/venv/bin/python" tests/protocols/opcua_client.py "$ALBA" "$OUT/plant"
# Alba as a Modbus TCP master (--io modbus) against a pymodbus slave.
rm -rf "$OUT/master"
cp -r tests/protocols/master "$OUT/master"
"$OUT/venv/bin/python" tests/protocols/modbus_master.py "$ALBA" "$OUT/master"
# OPC UA security (users, Basic256Sha256, certificate trust) against asyncua.
rm -rf "$OUT/plant"
cp -r tests/protocols/plant "$OUT/plant"
"$OUT/venv/bin/python" tests/protocols/opcua_security.py "$ALBA" "$OUT/plant"
# Alba as an OPC UA client ([[opcua_server]]) against asyncua's server: a wrong password and
# an untrusted server certificate refused, subscription and writes.
rm -rf "$OUT/opcua_io"
cp -r tests/protocols/opcua_io "$OUT/opcua_io"
"$OUT/venv/bin/python" tests/protocols/opcua_client_io.py "$ALBA" "$OUT/opcua_io"
# The MQTT client (--mqtt) against a Mosquitto broker and paho-mqtt (a fresh copy again).
rm -rf "$OUT/plant"
cp -r tests/protocols/plant "$OUT/plant"
"$OUT/venv/bin/python" tests/protocols/mqtt_client.py "$ALBA" "$OUT/plant"
# Sparkplug B ([mqtt.sparkplug]) decoded and commanded with pysparkplug (it copies the project itself).
"$OUT/venv/bin/python" tests/protocols/sparkplug_client.py "$ALBA" tests/protocols/plant
