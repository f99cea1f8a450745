"""`alba run` as a child process for the protocol scripts: started with an
ephemeral HTTP port (read from its output), its HTTP API, its output kept."""

import json
import re
import socket
import subprocess
import threading
import time
import urllib.request


class Alba:
    def __init__(self, binary, project, io):
        self.proc = subprocess.Popen(
            [binary, "run", project, "--http", "127.0.0.1:0", "--io", io, "--no-native"],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        self.http = None
        self.log = []
        deadline = time.time() + 60
        while time.time() < deadline and not self.http:
            line = self.proc.stdout.readline()
            if not line:
                raise SystemExit(f"alba run ended: exit {self.proc.wait()}: {''.join(self.log)}")
            self.log.append(line)
            m = re.search(r"http://([\d.]+:\d+)/", line)
            if m:
                self.http = "http://" + m.group(1)
        if not self.http:
            raise SystemExit("alba run did not report its address")
        threading.Thread(target=self._drain, daemon=True).start()

    def _drain(self):
        for line in self.proc.stdout:
            self.log.append(line)

    def api(self, method, path, body=None):
        data = None if body is None else json.dumps(body).encode()
        req = urllib.request.Request(self.http + path, data=data, method=method,
                                     headers={"Content-Type": "application/json"})
        with urllib.request.urlopen(req, timeout=10) as r:
            return json.loads(r.read() or b"null")

    def tag(self, name):
        return self.api("GET", f"/api/tags/{name}")["value"]

    def said(self, text):
        return any(text in l for l in self.log)

    def stop(self):
        self.proc.terminate()
        try:
            self.proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            self.proc.kill()


def free_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port
