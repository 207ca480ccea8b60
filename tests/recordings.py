"""Reading rerun recordings back in the tests."""

import rerun.chunk as rc


def content(path):
    """Entities, timelines and values of a recording, without rerun's row and chunk ids
    (time-based by design)."""
    chunks = []
    for chunk in rc.RrdReader(path).store().stream().to_chunks():
        batch = chunk.to_record_batch()
        keep = [i for i, f in enumerate(batch.schema)
                if (f.metadata or {}).get(b"rerun:kind") != b"control"]
        cols = {batch.schema.field(i).name: batch.column(i).to_pylist() for i in keep}
        chunks.append((chunk.entity_path, chunk.is_static, repr(sorted(cols.items()))))
    return sorted(chunks)
