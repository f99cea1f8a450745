#!/usr/bin/env python3
"""OPC UA security of `alba run --opcua` against the asyncua client.

Usage: opcua_security.py ALBA_BINARY PROJECT_DIR

The project gets an `[opcua.users]` entry whose hash `alba hash-password`
makes (deprecated, still loaded: `operator` an operator, `viewer` in read_only a
viewer), and two users of the common store, users.toml, added with `alba user
add` (password on stdin): `tech` (operator) and `display` (viewer). Then:

1. Bound to loopback (127.0.0.2): the endpoints are None and Basic256Sha256
   Sign / SignAndEncrypt; Basic256Sha256 + SignAndEncrypt with the user name
   and password reads and writes (and an input stays read-only); Sign works
   too; a read-only user reads and may not write; the users.toml operator
   reads and writes and the users.toml viewer may not write; a wrong password, an unknown user and anonymous on a secure endpoint
   are refused; None + anonymous works; the server's key pair was created,
   its private key mode 0600. Prints the handshake time and the
   read rate with SignAndEncrypt and with None.
2. Bound to 0.0.0.0 (the client still talks to 127.0.0.1): no None endpoint
   is offered and a None connection is refused; an unknown client
   certificate is refused and lands in .alba/pki/rejected/; moved to
   .alba/pki/trusted/ it is accepted, and then the user reads and writes;
   anonymous and a wrong password are refused.
3. `alba run --opcua 0.0.0.0:0` of a project without users refuses to start.
"""

import asyncio
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.request
from pathlib import Path

from asyncua import Client, ua
from asyncua.crypto.cert_gen import setup_self_signed_certificate
from asyncua.crypto.security_policies import SecurityPolicyBasic256Sha256
from cryptography.x509.oid import ExtendedKeyUsageOID

PASSWORD = "correct horse battery staple"
CLIENT_URI = "urn:alba:test:asyncua"
failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print(f"  FAIL: {what}", flush=True)


def start(binary, project, opcua):
    p = subprocess.Popen([binary, "run", project, "--http", "127.0.0.1:0", "--opcua", opcua, "--no-native"],
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    port = http = None
    deadline = time.time() + 60
    while time.time() < deadline and not (port and http):
        line = p.stdout.readline()
        if not line:
            raise SystemExit(f"alba run ended: exit {p.wait()}")
        m = re.search(r"OPC UA server: opc\.tcp://[\d.]+:(\d+)/", line)
        if m:
            port = int(m.group(1))
        m = re.search(r"http://([\d.]+:\d+)/", line)
        if m:
            http = "http://" + m.group(1)
    if not (port and http):
        raise SystemExit("alba run did not report its addresses")
    threading.Thread(target=p.stdout.read, daemon=True).start()
    return p, port, http


def stop(p):
    p.terminate()
    try:
        p.wait(timeout=20)
    except subprocess.TimeoutExpired:
        p.kill()


TOKENS = {}


def api(http, path):
    """GET `path`; when the API asks for a session (the project has users),
    log in once as the store's operator and send its bearer token."""
    headers = {"Authorization": f"Bearer {TOKENS[http]}"} if http in TOKENS else {}
    try:
        with urllib.request.urlopen(urllib.request.Request(http + path, headers=headers), timeout=10) as r:
            return json.loads(r.read())
    except urllib.error.HTTPError as e:
        if e.code != 401 or http in TOKENS:
            raise
    body = json.dumps({"user": "tech", "password": PASSWORD}).encode()
    login = urllib.request.Request(http + "/api/login", data=body, method="POST",
                                   headers={"Content-Type": "application/json", "Origin": http})
    with urllib.request.urlopen(login, timeout=10) as r:
        TOKENS[http] = json.loads(r.read())["token"]
    return api(http, path)


async def secure_client(url, cert, key, user=None, password=None, mode=ua.MessageSecurityMode.SignAndEncrypt):
    c = Client(url=url, timeout=10)
    c.application_uri = CLIENT_URI
    await c.set_security(SecurityPolicyBasic256Sha256, str(cert), str(key), mode=mode)
    if user is not None:
        c.set_user(user)
        c.set_password(password)
    return c


async def refused(make, what):
    """`make()` builds a client; connecting it must fail."""
    c = await make()
    try:
        await c.connect()
    except Exception as e:  # asyncua raises several kinds (status codes, closed channels)
        print(f"  refused as expected: {what}: {type(e).__name__}: {str(e)[:100]}", flush=True)
        return
    check(False, f"accepted: {what}")
    await c.disconnect()


async def server_refuses(url, user, what):
    """A security None session (anonymous, or `user` with the password) must
    be refused by the server itself: asyncua's own check that the endpoint
    exists is bypassed."""
    orig = Client.find_endpoint

    def any_endpoint(endpoints, mode, uri):
        try:
            return orig(endpoints, mode, uri)
        except ua.UaError:
            token = ua.UserTokenPolicy(PolicyId="userpass_none" if user else "anonymous",
                                       TokenType=ua.UserTokenType.UserName if user else ua.UserTokenType.Anonymous)
            return ua.EndpointDescription(EndpointUrl=url, SecurityMode=mode, SecurityPolicyUri=uri,
                                          UserIdentityTokens=[token])

    Client.find_endpoint = staticmethod(any_endpoint)
    try:
        c = Client(url=url, timeout=10)
        if user:
            c.set_user(user)
            c.set_password(PASSWORD)
        try:
            await c.connect()
        except ua.UaStatusCodeError as e:
            print(f"  refused by the server as expected: {what}: {e.code:#x} {str(e)[:80]}", flush=True)
            return
        except Exception as e:
            check(False, f"{what}: not a refusal by the server: {type(e).__name__}: {e}")
            return
        check(False, f"accepted: {what}")
        await c.disconnect()
    finally:
        Client.find_endpoint = staticmethod(orig)


async def read_write(c, http, ns, value):
    speed = c.get_node(f"ns={ns};s=Speed")
    await speed.write_value(ua.DataValue(ua.Variant(value, ua.VariantType.Int32)))
    check(api(http, "/api/tags/Speed")["value"] == value, f"secure write of {value} reached the engine")
    check(await speed.read_value() == value, "secure read back")
    start_btn = c.get_node(f"ns={ns};s=Start")
    before = api(http, "/api/tags/Start")["value"]
    try:
        await start_btn.write_value(ua.DataValue(ua.Variant(not before, ua.VariantType.Boolean)))
        check(False, "a secure session wrote the input Start")
    except ua.UaStatusCodeError as e:
        check(e.code in (ua.StatusCodes.BadNotWritable, ua.StatusCodes.BadUserAccessDenied),
              f"input write refused with {e}")
    check(api(http, "/api/tags/Start")["value"] == before, "the input is unchanged")


async def read_rate(c, ns, seconds=2.0):
    node = c.get_node(f"ns={ns};s=Scans")
    n = 0
    t0 = time.perf_counter()
    while time.perf_counter() - t0 < seconds:
        await node.read_value()
        n += 1
    return n / (time.perf_counter() - t0)


async def handshake_ms(make, times=5):
    out = []
    for _ in range(times):
        c = await make()
        t0 = time.perf_counter()
        await c.connect()
        out.append((time.perf_counter() - t0) * 1000)
        await c.disconnect()
    return statistics.median(out)


async def loopback(binary, project, cert, key):
    print("OPC UA security on loopback (127.0.0.2)", flush=True)
    proc, port, http = start(binary, project, "127.0.0.2:0")
    url = f"opc.tcp://127.0.0.2:{port}/"
    try:
        key_file = Path(project) / ".alba" / "pki" / "private" / "private.pem"
        check(key_file.is_file() and key_file.stat().st_mode & 0o777 == 0o600,
              "the server's private key was created on first run, readable by its owner only")
        async with Client(url=url, timeout=10) as probe:
            eps = await probe.get_endpoints()
        kinds = sorted((e.SecurityPolicyUri.split("#")[-1], e.SecurityMode.name) for e in eps)
        check(kinds == [("Basic256Sha256", "Sign"), ("Basic256Sha256", "SignAndEncrypt"), ("None", "None_")],
              f"loopback endpoints: {kinds}")
        for e in eps:
            tokens = sorted(t.TokenType.name for t in e.UserIdentityTokens)
            want = ["Anonymous"] if e.SecurityMode == ua.MessageSecurityMode.None_ else ["UserName"]
            check(tokens == want, f"{e.SecurityPolicyUri} {e.SecurityMode.name}: tokens {tokens}")
        c = await secure_client(url, cert, key, "operator", PASSWORD)
        async with c:
            ns = await c.get_namespace_index("urn:alba:modbus-plant")
            await read_write(c, http, ns, 1234)
            enc_rate = await read_rate(c, ns)
        # Users of the common store (users.toml): an operator reads and
        # writes, a viewer reads and its writes are refused.
        c = await secure_client(url, cert, key, "tech", PASSWORD)
        async with c:
            await read_write(c, http, ns, 2468)
        c = await secure_client(url, cert, key, "display", PASSWORD)
        async with c:
            speed = c.get_node(f"ns={ns};s=Speed")
            check(await speed.read_value() == 2468, "the users.toml viewer reads")
            try:
                await speed.write_value(ua.DataValue(ua.Variant(5, ua.VariantType.Int32)))
                check(False, "a users.toml viewer wrote Speed")
            except ua.UaStatusCodeError as e:
                check(e.code == ua.StatusCodes.BadUserAccessDenied, f"users.toml viewer write refused with {e}")
        c = await secure_client(url, cert, key, "operator", PASSWORD, mode=ua.MessageSecurityMode.Sign)
        async with c:
            await read_write(c, http, ns, 4321)
        # A read-only user reads, and its writes are refused.
        c = await secure_client(url, cert, key, "viewer", PASSWORD)
        async with c:
            speed = c.get_node(f"ns={ns};s=Speed")
            check(await speed.read_value() == 4321, "the read-only user reads")
            try:
                await speed.write_value(ua.DataValue(ua.Variant(1, ua.VariantType.Int32)))
                check(False, "a read-only user wrote Speed")
            except ua.UaStatusCodeError as e:
                check(e.code == ua.StatusCodes.BadUserAccessDenied, f"read-only write refused with {e}")
            check(api(http, "/api/tags/Speed")["value"] == 4321, "a refused write changes nothing")
        await refused(lambda: secure_client(url, cert, key, "operator", "wrong"), "a wrong password")
        await refused(lambda: secure_client(url, cert, key, "nobody", PASSWORD), "an unknown user")
        await refused(lambda: secure_client(url, cert, key), "anonymous on Basic256Sha256")
        async with Client(url=url, timeout=10) as c:
            check(await c.get_node(f"ns={ns};s=Speed").read_value() == 4321, "None + anonymous reads on loopback")
            none_rate = await read_rate(c, ns)

        async def plain():
            return Client(url=url, timeout=10)

        hs_none = await handshake_ms(plain)
        hs_enc = await handshake_ms(lambda: secure_client(url, cert, key, "operator", PASSWORD))
        print(f"  handshake (connect + session, median of 5): None {hs_none:.1f} ms, "
              f"Basic256Sha256 SignAndEncrypt + password {hs_enc:.1f} ms", flush=True)
        print(f"  sequential reads, one client: None {none_rate:.0f}/s, SignAndEncrypt {enc_rate:.0f}/s", flush=True)
    finally:
        stop(proc)


async def wide(binary, project, cert, key):
    print("OPC UA security bound to 0.0.0.0 (client on 127.0.0.1)", flush=True)
    pki = Path(project) / ".alba" / "pki"
    proc, port, http = start(binary, project, "0.0.0.0:0")
    url = f"opc.tcp://127.0.0.1:{port}/"
    try:
        c = Client(url=url, timeout=10)
        eps = await c.connect_and_get_server_endpoints()
        kinds = sorted((e.SecurityPolicyUri.split("#")[-1], e.SecurityMode.name) for e in eps)
        check(kinds == [("Basic256Sha256", "Sign"), ("Basic256Sha256", "SignAndEncrypt")], f"0.0.0.0 endpoints: {kinds}")
        check(all(t.TokenType == ua.UserTokenType.UserName for e in eps for t in e.UserIdentityTokens),
              "only user names and passwords beyond loopback")
        # asyncua would stop by itself on seeing no None endpoint; make it
        # try anyway, so that the refusal is the server's.
        await server_refuses(url, None, "None + anonymous")
        await server_refuses(url, "operator", "None + a user name and password")
        # An unknown client certificate: refused and kept for the administrator.
        await refused(lambda: secure_client(url, cert, key, "operator", PASSWORD), "an untrusted client certificate")
        rejected = list((pki / "rejected").glob("*.der"))
        check(len(rejected) == 1, f"the client certificate is in pki/rejected: {rejected}")
        for f in rejected:
            shutil.move(f, pki / "trusted" / f.name)
        c = await secure_client(url, cert, key, "operator", PASSWORD)
        async with c:
            ns = await c.get_namespace_index("urn:alba:modbus-plant")
            await read_write(c, http, ns, 777)
        await refused(lambda: secure_client(url, cert, key, "operator", "wrong"), "a wrong password")
        await refused(lambda: secure_client(url, cert, key), "anonymous on Basic256Sha256")
    finally:
        stop(proc)


def no_users_refused(binary, project):
    print("alba run --opcua 0.0.0.0:0 without [opcua.users]", flush=True)
    r = subprocess.run([binary, "run", project, "--http", "127.0.0.1:0", "--opcua", "0.0.0.0:0", "--no-native"],
                       capture_output=True, text=True, timeout=60)
    check(r.returncode != 0 and "[opcua.users]" in r.stderr, f"refused to start: {r.returncode} {r.stderr[-300:]}")


async def main():
    binary, project = sys.argv[1], sys.argv[2]
    no_users_refused(binary, project)
    h = subprocess.run([binary, "hash-password"], input=PASSWORD + "\n", capture_output=True, text=True, check=True)
    digest = h.stdout.strip()
    check(digest.startswith("$argon2id$"), f"alba hash-password: {digest}")
    with open(Path(project) / "alba.toml", "a") as f:
        f.write(f'\n[opcua]\nread_only = ["viewer"]\n[opcua.users]\noperator = "{digest}"\nviewer = "{digest}"\n')
    for name, role in (("tech", "operator"), ("display", "viewer")):
        r = subprocess.run([binary, "user", "add", project, name, "--role", role], input=PASSWORD + "\n",
                           capture_output=True, text=True)
        check(r.returncode == 0, f"alba user add {name}: {r.stderr[-300:]}")
    r = subprocess.run([binary, "user", "list", project], capture_output=True, text=True)
    check("tech\toperator" in r.stdout and "display\tviewer" in r.stdout and "argon2" not in r.stdout,
          f"alba user list: {r.stdout}")
    out = Path(project) / "client-pki"
    out.mkdir(exist_ok=True)
    cert, key = out / "client.der", out / "client.pem"
    await setup_self_signed_certificate(key, cert, CLIENT_URI, "localhost", [ExtendedKeyUsageOID.CLIENT_AUTH],
                                        {"commonName": "alba-test-client"})
    await loopback(binary, project, cert, key)
    # A fresh PKI: loopback trusted the client certificate on first use.
    shutil.rmtree(Path(project) / ".alba" / "pki")
    await wide(binary, project, cert, key)
    if failures:
        print(f"{len(failures)} check(s) failed", flush=True)
        sys.exit(1)
    print("OPC UA security tests passed", flush=True)


if __name__ == "__main__":
    os.environ.setdefault("PYTHONUNBUFFERED", "1")
    asyncio.run(main())
