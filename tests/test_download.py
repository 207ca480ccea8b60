"""The download path against a loopback HTTP server serving a small archive."""

import hashlib
import http.server
import io
import json
import threading
import zipfile

import pytest

from alfa_bench.data import AlfaDataError, build_manifest, fetch_alfa


def make_zip(processed, prefix="processed/"):
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        for f in sorted(processed.rglob("*.csv")):
            z.write(f, prefix + str(f.relative_to(processed)))
    return buf.getvalue()


@pytest.fixture
def server():
    """A loopback server: /api lists one file as figshare does; /file/1 serves it."""
    state = {}

    class Handler(http.server.BaseHTTPRequestHandler):
        def do_GET(self):
            body = state["api"] if self.path == "/api" else state["files"].get(self.path)
            if body is None:
                self.send_error(404)
                return
            self.send_response(200)
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            self.wfile.write(body)

        def log_message(self, *args):
            pass

    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
    base = f"http://127.0.0.1:{httpd.server_address[1]}"
    thread = threading.Thread(target=httpd.serve_forever, daemon=True)
    thread.start()

    def publish(archive: bytes, md5: str | None = None, name="processed.zip"):
        state["files"] = {"/file/1": archive}
        state["api"] = json.dumps([{
            "id": 1, "name": name, "size": len(archive), "is_link_only": False,
            "download_url": f"{base}/file/1",
            "computed_md5": md5 or hashlib.md5(archive).hexdigest(),
        }]).encode()
        return f"{base}/api"

    yield publish
    httpd.shutdown()


@pytest.mark.parametrize("prefix", ["processed/", "ALFA/processed/", ""])
def test_download_verify_unpack(server, corpus, tmp_path, prefix):
    archive = make_zip(corpus, prefix)
    api = server(archive)
    root = fetch_alfa(api, "processed.zip", tmp_path / "alfa",
                      sha256=hashlib.sha256(archive).hexdigest())
    assert root == tmp_path / "alfa"
    assert len(build_manifest(root / "processed")) == len(list(corpus.iterdir()))


def test_md5_mismatch_is_refused(server, corpus, tmp_path):
    api = server(make_zip(corpus), md5="0" * 32)
    with pytest.raises(AlfaDataError, match="MD5"):
        fetch_alfa(api, "processed.zip", tmp_path / "alfa")
    assert not (tmp_path / "alfa" / "processed").exists()
    assert not list((tmp_path / "alfa").glob("*.part"))


def test_pinned_sha256_mismatch_is_refused(server, corpus, tmp_path):
    api = server(make_zip(corpus))
    with pytest.raises(AlfaDataError, match="SHA-256"):
        fetch_alfa(api, "processed.zip", tmp_path / "alfa", sha256="f" * 64)


def test_missing_file_lists_what_is_there(server, corpus, tmp_path):
    api = server(make_zip(corpus), name="raw.zip")
    with pytest.raises(AlfaDataError, match=r"no file 'processed.zip' \(it has: raw.zip\)"):
        fetch_alfa(api, "processed.zip", tmp_path / "alfa")


def test_unsafe_member_path_is_refused(server, tmp_path):
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        z.writestr("../evil.csv", "x")
    api = server(buf.getvalue())
    with pytest.raises(AlfaDataError, match="unsafe path"):
        fetch_alfa(api, "processed.zip", tmp_path / "alfa")
    assert not (tmp_path / "evil.csv").exists()
