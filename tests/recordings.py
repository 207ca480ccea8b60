"""Reading rerun recordings back in the tests."""

import hashlib

import rerun.chunk as rc


def content(path):
    """Each chunk's entity, whether it is static, and a digest of its timelines and
    values, without rerun's row and chunk ids (time-based by design). The digest is of
    the chunk's Arrow IPC bytes, so a file of hundreds of chunks compares in milliseconds
    rather than through Python lists."""
    chunks = []
    for chunk in rc.RrdReader(path).store().stream().to_chunks():
        batch = chunk.to_record_batch()
        kept = batch.select([f.name for f in batch.schema
                             if (f.metadata or {}).get(b"rerun:kind") != b"control"])
        kept = kept.select(sorted(kept.schema.names))
        digest = hashlib.sha256(kept.serialize()).hexdigest()
        chunks.append((chunk.entity_path, chunk.is_static, digest))
    return sorted(chunks)
