"""Writes seeds/rosbag/husky_head.bag: the first two messages of each topic of
husky_gps.bag in one bz2 chunk and one uncompressed chunk, with connection,
index and chunk-info records, so that fuzzing starts from real messages."""
import bz2, struct, sys

SRC = sys.argv[1] if len(sys.argv) > 1 else "../../../../shared/data/husky-gps-bag/husky_gps.bag"

def records(buf, pos=0):
    while pos < len(buf):
        hl = struct.unpack_from("<I", buf, pos)[0]; h = buf[pos + 4:pos + 4 + hl]
        dl = struct.unpack_from("<I", buf, pos + 4 + hl)[0]
        d = buf[pos + 8 + hl:pos + 8 + hl + dl]
        f, i = {}, 0
        while i < len(h):
            n = struct.unpack_from("<I", h, i)[0]; k, v = h[i + 4:i + 4 + n].split(b"=", 1); f[k] = v; i += 4 + n
        yield f, d
        pos += 8 + hl + dl

def rec(fields, data):
    h = b"".join(struct.pack("<I", len(k) + 1 + len(v)) + k + b"=" + v for k, v in fields)
    return struct.pack("<I", len(h)) + h + struct.pack("<I", len(data)) + data

src = open(SRC, "rb").read()
conns, msgs = {}, {}
for f, d in records(src, 13):
    if f[b"op"] == b"\x05":
        for g, e in records(bz2.decompress(d)):
            c = struct.unpack("<I", g[b"conn"])[0]
            if g[b"op"] == b"\x07":
                conns[c] = rec([(b"op", b"\x07"), (b"conn", g[b"conn"]), (b"topic", g[b"topic"])], e)
            elif len(msgs.setdefault(c, [])) < 2:
                msgs[c].append((g[b"time"], rec([(b"op", b"\x02"), (b"conn", g[b"conn"]), (b"time", g[b"time"])], e)))
        break
out = bytearray(b"#ROSBAG V2.0\n")
hdr_len = len(rec([(b"op", b"\x03"), (b"index_pos", b"\0" * 8), (b"conn_count", b"\0" * 4), (b"chunk_count", b"\0" * 4)], b""))
body, index = bytearray(), bytearray()
for n, (comp, pick) in enumerate([(b"bz2", 0), (b"none", 1)]):
    inner, offs = bytearray(), {}
    for c in sorted(conns):
        inner += conns[c]
    for c in sorted(msgs):
        offs[c] = (msgs[c][pick][0], len(inner)); inner += msgs[c][pick][1]
    data = bz2.compress(bytes(inner)) if comp == b"bz2" else bytes(inner)
    chunk_pos = 13 + hdr_len + len(body)
    body += rec([(b"op", b"\x05"), (b"compression", comp), (b"size", struct.pack("<I", len(inner)))], data)
    for c, (t, o) in offs.items():
        body += rec([(b"op", b"\x04"), (b"ver", struct.pack("<I", 1)), (b"conn", struct.pack("<I", c)), (b"count", struct.pack("<I", 1))], t + struct.pack("<I", o))
    ts = [t for t, _ in offs.values()]
    index += rec([(b"op", b"\x06"), (b"ver", struct.pack("<I", 1)), (b"chunk_pos", struct.pack("<Q", chunk_pos)),
                  (b"start_time", min(ts)), (b"end_time", max(ts)), (b"count", struct.pack("<I", len(offs)))],
                 b"".join(struct.pack("<II", c, 1) for c in offs))
index_pos = 13 + hdr_len + len(body)
out += rec([(b"op", b"\x03"), (b"index_pos", struct.pack("<Q", index_pos)), (b"conn_count", struct.pack("<I", len(conns))),
            (b"chunk_count", struct.pack("<I", 2))], b"")
out += body
for c in sorted(conns):
    out += conns[c]
out += index
open("seeds/rosbag/husky_head.bag", "wb").write(out)
print(len(out), "bytes")
