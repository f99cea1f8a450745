#!/usr/bin/env python3
"""Alba as a Modbus TCP master (`alba run --io modbus`) against a slave
written elsewhere: pymodbus's TCP server.

Usage: modbus_master.py ALBA_BINARY PROJECT_DIR

The slave runs in this process (its data is set and read directly). The
project (tests/protocols/master) maps the slave's discrete inputs 0-3 and
input registers 0-1 onto DI/AI, and its coils 0-3 and holding registers
10-11 onto DO/AO; its ladder copies inputs to outputs. Checks: inputs set
on the slave come back on its coils and registers through the program;
S:IOOK true while the slave answers; the slave killed → S:IOOK false and
S:IOERRORS counting, the program keeps scanning; the slave restarted →
recovery, outputs written again at once. Then the same device under a
state net (io.pnml, run instead of the ladder): its Input element reads
input register 0, its Output element writes twice that to holding register
10 while marked, Conditions on discrete input 0 move the token. Then the ladder again over Modbus RTU.
Prints the measured poll rate and recovery time.
"""

import asyncio
import json
import logging
import os
import re
import sys
import threading
import time
import tty

from pymodbus.datastore import ModbusDeviceContext, ModbusSequentialDataBlock, ModbusServerContext
from pymodbus import FramerType
from pymodbus.server import ModbusSerialServer, ModbusTcpServer
from alba_run import Alba, free_port

failures = []
# pymodbus 3.16 warns that its classic datastore is deprecated (v4 replaces it).
logging.getLogger("pymodbus.logging").setLevel(logging.ERROR)


def check(cond, what):
    if not cond:
        failures.append(what)
        print(f"  FAIL: {what}", flush=True)


def until(what, f, timeout=10.0):
    deadline = time.time() + timeout
    while time.time() < deadline:
        if f():
            return True
        time.sleep(0.01)
    check(False, f"timed out waiting for {what}")
    return False


class Slave:
    """A pymodbus TCP slave on its own event loop thread; counts requests."""

    def __init__(self, port, serial=None):
        self.port = port
        self.serial = serial
        self.requests = 0
        self.loop = asyncio.new_event_loop()
        threading.Thread(target=self.loop.run_forever, daemon=True).start()
        self.server = None

    def _run(self, coro, timeout=10):
        return asyncio.run_coroutine_threadsafe(coro, self.loop).result(timeout)

    def start(self):
        async def go():
            dev = ModbusDeviceContext(
                di=ModbusSequentialDataBlock(1, [False] * 64),
                co=ModbusSequentialDataBlock(1, [False] * 64),
                ir=ModbusSequentialDataBlock(1, [0] * 64),
                hr=ModbusSequentialDataBlock(1, [0] * 64),
            )

            def trace(sending, pdu):
                if not sending:
                    self.requests += 1
                return pdu

            ctx = ModbusServerContext(devices=dev, single=True)
            if self.serial:
                self.server = ModbusSerialServer(ctx, framer=FramerType.RTU, port=self.serial,
                                                 baudrate=19200, trace_pdu=trace)
            else:
                self.server = ModbusTcpServer(ctx, address=("127.0.0.1", self.port), trace_pdu=trace)
            await self.server.serve_forever(background=True)

        self._run(go())

    def stop(self):
        async def go():
            await self.server.shutdown()

        self._run(go())
        self.server = None

    def set(self, fc, addr, values):
        async def go():
            return await self.server.context.async_setValues(1, fc, addr, values)

        return self._run(go())

    def get(self, fc, addr, count):
        async def go():
            return await self.server.context.async_getValues(1, fc, addr, count)

        return self._run(go())



def serial_line():
    """Two ptys joined back to back (a null-modem cable): returns their paths."""
    ends = []
    for _ in range(2):
        master, slave = os.openpty()
        tty.setraw(slave)
        ends.append((master, slave, os.ttyname(slave)))

    def pump(a, b):
        while True:
            try:
                data = os.read(a, 4096)
                if not data:
                    return
                os.write(b, data)
            except OSError:
                time.sleep(0.01)

    threading.Thread(target=pump, args=(ends[0][0], ends[1][0]), daemon=True).start()
    threading.Thread(target=pump, args=(ends[1][0], ends[0][0]), daemon=True).start()
    return ends[0][2], ends[1][2]


def rtu(binary, project):
    """The same project with the device on a serial line (Modbus RTU)."""
    alba_end, slave_end = serial_line()
    toml = f"{project}/alba.toml"
    text = open(toml).read()
    open(toml, "w").write(re.sub(r'tcp = "[^"]*"', f'rtu = "{alba_end}"\nbaud = 19200', text))
    slave = Slave(0, serial=slave_end)
    slave.start()
    alba = Alba(binary, project, "modbus")
    try:
        print(f"modbus master RTU ({alba_end} <-> {slave_end}): inputs to outputs", flush=True)
        until("S:IOOK (RTU)", lambda: alba.tag("S:IOOK") is True)
        slave.set(2, 0, [True, False, True, True])
        slave.set(4, 0, [300, 5])
        until("coils 0-3 (RTU)", lambda: slave.get(1, 0, 4) == [True, True, True, True])
        until("holding registers 10-11 (RTU)", lambda: slave.get(3, 10, 2) == [300, 6])
        n0, t0 = slave.requests, time.time()
        time.sleep(2)
        print(f"  slave served {(slave.requests - n0) / (time.time() - t0):.0f} requests/s at 19200 baud", flush=True)
        slave.stop()
        until("S:IOOK false (RTU)", lambda: alba.tag("S:IOOK") is False)
        slave.start()
        t_up = time.time()
        until("S:IOOK true again (RTU)", lambda: alba.tag("S:IOOK") is True)
        until("outputs restored (RTU)", lambda: slave.get(1, 0, 4) == [False, True, False, True])
        print(f"  recovered {time.time() - t_up:.3f} s after the slave restarted", flush=True)
    finally:
        alba.stop()
        slave.stop()


def net(binary, project, port):
    """The same device with a state net instead of the ladder (io.pnml): its
    Input element reads input register 0, its Output element writes holding
    register 10, Conditions on discrete input 0 move the token."""
    toml = f"{project}/alba.toml"
    text = open(toml).read()
    open(toml, "w").write(text.replace('programs = ["main.lad"]', 'programs = ["io.pnml"]'))
    slave = Slave(port)
    slave.start()
    alba = Alba(binary, project, "modbus")
    try:
        print("modbus master: a net's Input and Output elements on the slave's registers", flush=True)
        until("S:IOOK (net)", lambda: alba.tag("S:IOOK") is True)
        # In normal mode a token waits in the transition whose guard is false.
        check(alba.tag("io.go") == 1, f"the token waits at io.go: {alba.tag('io.go')}")
        slave.set(4, 0, [21])
        slave.set(2, 0, [True])
        until("the token at io.back", lambda: alba.tag("io.back") == 1)
        check(alba.tag("io.level.value") == 21, f"the Input element read 21: {alba.tag('io.level.value')}")
        until("holding register 10 = 2 x 21 from the Output element", lambda: slave.get(3, 10, 1) == [42])
        slave.set(2, 0, [False])
        until("the token back at io.go", lambda: alba.tag("io.go") == 1)
        slave.set(4, 0, [50])
        time.sleep(0.3)
        check(slave.get(3, 10, 1) == [42], "unmarked, the Output element writes nothing")
        slave.set(2, 0, [True])
        until("holding register 10 = 100", lambda: slave.get(3, 10, 1) == [100])
    finally:
        alba.stop()
        slave.stop()
    open(toml, "w").write(text)


def main():
    binary, project = sys.argv[1], sys.argv[2]
    port = free_port()
    toml = f"{project}/alba.toml"
    text = open(toml).read()
    open(toml, "w").write(re.sub(r'tcp = "127\.0\.0\.1:\d+"', f'tcp = "127.0.0.1:{port}"', text))
    slave = Slave(port)
    slave.start()
    alba = Alba(binary, project, "modbus")
    try:
        print("modbus master: inputs of the slave through the program to its outputs", flush=True)
        until("S:IOOK", lambda: alba.tag("S:IOOK") is True)
        slave.set(2, 0, [True, True, True, False])
        slave.set(4, 0, [1234, 65535])  # 65535 is INT -1
        until("coils 0-3", lambda: slave.get(1, 0, 4) == [True, False, False, True])
        until("holding registers 10-11", lambda: slave.get(3, 10, 2) == [1234, 0])
        check(alba.tag("Raw1") == -1, f"Raw1 is -1: {alba.tag('Raw1')}")
        slave.set(2, 3, [True])
        slave.set(4, 0, [7, 41])
        until("coil 2 (In2 and In3)", lambda: slave.get(1, 2, 1) == [True])
        until("holding registers 10-11 follow", lambda: slave.get(3, 10, 2) == [7, 42])
        # Poll rate: requests the slave served in a second (4 blocks a poll,
        # writes only on change or refresh).
        n0, t0 = slave.requests, time.time()
        time.sleep(2)
        rate = (slave.requests - n0) / (time.time() - t0)
        print(f"  slave served {rate:.0f} requests/s (poll_ms = 20: 2 reads a poll + writes)", flush=True)
        check(rate > 20, f"polling at {rate:.1f} requests/s")
        # A write to the slave's coil behind Alba's back is corrected by the
        # periodic refresh (refresh_ms = 500).
        slave.set(1, 0, [False])
        until("coil 0 refreshed", lambda: slave.get(1, 0, 1) == [True], timeout=5)

        print("modbus master: slave killed", flush=True)
        errors0 = alba.tag("S:IOERRORS")
        slave.stop()
        t_kill = time.time()
        until("S:IOOK false", lambda: alba.tag("S:IOOK") is False)
        print(f"  loss noticed in {time.time() - t_kill:.3f} s", flush=True)
        until("S:IOERRORS counting", lambda: alba.tag("S:IOERRORS") > errors0)
        scans = alba.api("GET", "/api/status")
        time.sleep(0.5)
        scans2 = alba.api("GET", "/api/status")
        check(json.dumps(scans) != json.dumps(scans2), "the engine keeps scanning while the slave is down")
        check(alba.tag("Raw0") == 7, "inputs keep their last values")

        print("modbus master: slave restarted", flush=True)
        time.sleep(1.0)
        slave.start()  # fresh data: every coil and register 0
        t_up = time.time()
        until("S:IOOK true again", lambda: alba.tag("S:IOOK") is True)
        # The engine's outputs are written at once after the reconnection.
        until("outputs restored on the new slave", lambda: slave.get(1, 0, 4) == [False, True, False, True])
        print(f"  recovered (S:IOOK and outputs back) {time.time() - t_up:.3f} s after the restart", flush=True)
        slave.set(2, 0, [True])
        until("coil 0 follows again", lambda: slave.get(1, 0, 1) == [True])
    finally:
        alba.stop()
    # On stop the driver leaves the slave's outputs off.
    check(slave.get(1, 0, 4) == [False] * 4, f"coils off after alba stops: {slave.get(1, 0, 4)}")
    check(slave.get(3, 10, 2) == [0, 0], f"registers 0 after alba stops: {slave.get(3, 10, 2)}")
    slave.stop()
    out = "".join(alba.log)
    check("link lost" in out and "link up" in out, "alba announced the loss and the recovery")
    if failures:
        print("".join(alba.log[-30:]))
        raise SystemExit(f"modbus master: {len(failures)} failure(s)")
    net(binary, project, port)
    if failures:
        raise SystemExit(f"modbus master net: {len(failures)} failure(s)")
    rtu(binary, project)
    if failures:
        raise SystemExit(f"modbus master RTU: {len(failures)} failure(s)")
    print("modbus master: all passed", flush=True)


if __name__ == "__main__":
    main()
