"""The download path against a loopback server serving an archive laid out like ALFA's."""

import hashlib
import io
import socket
import zipfile

import pytest
from loopback import make_archive, serve_archive

from alfa_bench.data import DownloadError, build_manifest, fetch_alfa


@pytest.mark.parametrize("prefix", ["processed/", "ALFA/processed/", ""])
def test_download_verify_unpack_only_the_csvs(corpus, tmp_path, prefix):
    archive = make_archive(corpus, prefix)
    with serve_archive(archive) as (api, _):
        root = fetch_alfa(api, "processed.zip", tmp_path / "alfa",
                          md5=hashlib.md5(archive).hexdigest(),
                          sha256=hashlib.sha256(archive).hexdigest())
    assert root == tmp_path / "alfa"
    assert len(build_manifest(root / "processed")) == len(list(corpus.iterdir()))
    unpacked = {p.relative_to(root / "processed") for p in (root / "processed").rglob("*")
                if p.is_file()}
    assert unpacked == {p.relative_to(corpus) for p in corpus.rglob("*.csv")}
    assert not (tmp_path / "alfa" / ".unpacking").exists()


def test_a_verified_archive_is_not_downloaded_again(corpus, tmp_path):
    archive = make_archive(corpus)
    with serve_archive(archive) as (api, requests):
        fetch_alfa(api, "processed.zip", tmp_path / "alfa")
        fetch_alfa(api, "processed.zip", tmp_path / "alfa")
    assert requests.count("/file/1") == 1


def test_repository_md5_mismatch_is_refused(corpus, tmp_path):
    with serve_archive(make_archive(corpus), md5="0" * 32) as (api, _):
        with pytest.raises(DownloadError, match="MD5 .* the repository says 0{32}.*Run again"):
            fetch_alfa(api, "processed.zip", tmp_path / "alfa")
    assert not (tmp_path / "alfa" / "processed").exists()
    assert not list((tmp_path / "alfa").glob("processed.zip*"))


def test_pinned_md5_mismatch_is_refused(corpus, tmp_path):
    with serve_archive(make_archive(corpus)) as (api, _):
        with pytest.raises(DownloadError, match="the config says 792c.*download.md5"):
            fetch_alfa(api, "processed.zip", tmp_path / "alfa",
                       md5="792c36aef2fd1fd19a91a53e3b3dcfdf")
    assert not list((tmp_path / "alfa").glob("processed.zip*"))


def test_pinned_sha256_mismatch_is_refused(corpus, tmp_path):
    with serve_archive(make_archive(corpus)) as (api, _):
        with pytest.raises(DownloadError, match="SHA-256"):
            fetch_alfa(api, "processed.zip", tmp_path / "alfa", sha256="f" * 64)


def test_a_truncated_download_says_run_again(corpus, tmp_path):
    with serve_archive(make_archive(corpus), truncate=True) as (api, _):
        with pytest.raises(DownloadError) as e:
            fetch_alfa(api, "processed.zip", tmp_path / "alfa")
    assert "Run again" in str(e.value) and "ALFA_DIR" in str(e.value)
    assert not list((tmp_path / "alfa").glob("processed.zip*"))


def test_no_network_says_what_to_do(tmp_path):
    with socket.socket() as s:   # a port nothing listens on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    with pytest.raises(DownloadError, match=r"cannot reach .*doi.org/10.1184/R1/12707963.*"
                                            r"ALFA_DIR"):
        fetch_alfa(f"http://127.0.0.1:{port}/api", "processed.zip", tmp_path / "alfa")


def test_missing_file_lists_what_is_there(corpus, tmp_path):
    with serve_archive(make_archive(corpus), name="raw.zip") as (api, _):
        with pytest.raises(DownloadError,
                           match=r"no file 'processed.zip' \(it has: raw.zip\)"):
            fetch_alfa(api, "processed.zip", tmp_path / "alfa")


def test_unsafe_member_path_is_refused(tmp_path):
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        z.writestr("../evil.csv", "x")
    with serve_archive(buf.getvalue()) as (api, _):
        with pytest.raises(DownloadError, match="unsafe path"):
            fetch_alfa(api, "processed.zip", tmp_path / "alfa")
    assert not (tmp_path / "evil.csv").exists()
