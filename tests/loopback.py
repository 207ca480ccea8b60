"""A loopback stand-in for KiltHub: a figshare-like file listing and one archive.

``serve_archive(archive)`` yields the listing's URL. The archive is laid out as
ALFA's ``processed.zip`` (``make_archive``): per flight, its CSVs beside a ROS bag
and a MATLAB file, which the pipeline must leave in the archive.
"""

import contextlib
import hashlib
import http.server
import io
import json
import threading
import zipfile
from pathlib import Path


def make_archive(processed: Path, prefix: str = "processed/", extras: bool = True) -> bytes:
    """A zip of the flights under ``processed`` as ``prefix<flight>/<file>``: the same
    bytes for the same flights, whenever they were written (its MD5 is in the config)."""
    buf = io.BytesIO()

    def add(name: str, data: bytes) -> None:
        z.writestr(zipfile.ZipInfo(name, date_time=(2018, 7, 18, 0, 0, 0)), data)

    with zipfile.ZipFile(buf, "w") as z:
        for flight in sorted(p for p in processed.iterdir() if p.is_dir()):
            for f in sorted(flight.glob("*.csv")):
                add(f"{prefix}{flight.name}/{f.name}", f.read_bytes())
            if extras:
                add(f"{prefix}{flight.name}/{flight.name}.bag", b"#ROSBAG V2.0\n" * 64)
                add(f"{prefix}{flight.name}/{flight.name}.mat", b"MATLAB 5.0" * 64)
    return buf.getvalue()


@contextlib.contextmanager
def serve_archive(archive: bytes, *, name: str = "processed.zip", md5: str | None = None,
                  truncate: bool = False, port: int = 0):
    """Serve ``archive`` on 127.0.0.1; yield ``(api_url, requests)``, where
    ``requests`` lists the paths asked for. ``md5`` overrides the listed MD5;
    ``truncate`` breaks the connection half-way through the file. A ``port`` given is
    shared (SO_REUSEPORT) with the processes serving the same archive on it, as the
    test workers do: the kernel hands each connection to one of them."""
    requests: list[str] = []
    state: dict = {}

    class Handler(http.server.BaseHTTPRequestHandler):
        def do_GET(self):
            requests.append(self.path)
            body = state["api"] if self.path == "/api" else state["files"].get(self.path)
            if body is None:
                self.send_error(404)
                return
            self.send_response(200)
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            self.wfile.write(body[: len(body) // 2] if truncate and self.path != "/api"
                             else body)

        def log_message(self, *args):
            pass

    class Server(http.server.ThreadingHTTPServer):
        allow_reuse_port = bool(port)

    httpd = Server(("127.0.0.1", port), Handler)
    base = f"http://127.0.0.1:{httpd.server_address[1]}"
    state["files"] = {"/file/1": archive}
    state["api"] = json.dumps([{
        "id": 1, "name": name, "size": len(archive), "is_link_only": False,
        "download_url": f"{base}/file/1",
        "computed_md5": md5 or hashlib.md5(archive).hexdigest(),
    }]).encode()
    thread = threading.Thread(target=httpd.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"{base}/api", requests
    finally:
        httpd.shutdown()
        httpd.server_close()
