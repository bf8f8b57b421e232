"""Reading LCM log files from Python, with the message types lcm-gen generates at build time
(build/python/traverse/; Debian's LCM 1.3.1 has no Python module, and none is needed to read a
log). Used by scripts/demo.sh's progress display and scripts/examples/read_run_log.py.

The format (LCM's event log): each event is a big-endian header -- sync word 0xEDA1DA01, int64
event number, int64 timestamp [us], int32 channel length, int32 data length -- then the channel
name and the data. A log still being written ends in a partial event: events() stops before it
and tells where to resume.
"""
import os
import struct
import sys

SYNC = 0xEDA1DA01
HEADER = struct.Struct(">IqqII")


def events(path, offset=0, channels=None):
    """Yields (offset, timestamp_us, channel, data) from `offset` to the last complete event.
    With `channels` (a set), other channels' data is skipped unread and given as None."""
    with open(path, "rb") as f:
        f.seek(offset)
        while True:
            head = f.read(HEADER.size)
            if len(head) < HEADER.size:
                return
            sync, _number, utime, channel_len, data_len = HEADER.unpack(head)
            if sync != SYNC:
                raise ValueError(f"{path}: no event at byte {offset} (damaged log)")
            channel = f.read(channel_len)
            end = offset + HEADER.size + channel_len + data_len
            if len(channel) < channel_len:
                return  # partial: being written, or truncated
            channel = channel.decode("utf-8", "replace")
            if channels is None or channel in channels:
                data = f.read(data_len)
                if len(data) < data_len:
                    return
            else:
                if end > os.fstat(f.fileno()).st_size:
                    return
                f.seek(end)
                data = None
            yield offset, utime, channel, data
            offset = end


def message_types(build_dir=None):
    """{fingerprint bytes: class} for every generated type of package traverse."""
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    python_dir = os.path.join(build_dir or os.path.join(root, "build"), "python")
    if not os.path.isdir(os.path.join(python_dir, "traverse")):
        raise RuntimeError(f"no generated Python types in {python_dir} (build first: scripts/setup.sh)")
    if python_dir not in sys.path:
        sys.path.insert(0, python_dir)
    import traverse  # noqa: E402  (generated)

    types = {}
    for name in dir(traverse):
        cls = getattr(traverse, name)
        if isinstance(cls, type) and hasattr(cls, "_get_packed_fingerprint"):
            types[cls._get_packed_fingerprint()] = cls
    return types


def decode(types, data):
    """The message decoded with the type its fingerprint names, or None (unknown or damaged)."""
    cls = types.get(bytes(data[:8]))
    if cls is None:
        return None
    try:
        return cls.decode(data)
    except (ValueError, struct.error):
        return None


def write_events(path, items):
    """Writes (timestamp_us, channel, data) items as an LCM log, numbering the events from 0."""
    with open(path, "wb") as f:
        for number, (utime, channel, data) in enumerate(items):
            name = channel.encode("utf-8")
            f.write(HEADER.pack(SYNC, number, utime, len(name), len(data)))
            f.write(name)
            f.write(data)
