#!/usr/bin/env python3
"""An independent LAS 1.4 reader for the tests, written from the ASPRS LAS 1.4 R15 specification
(not from Traverse's writer): reads the public header, the VLRs (WKT and Extra Bytes), and every
point record of formats 6 to 8 with its extra bytes. Prints one JSON object: header fields, the
WKT, the extra-byte fields and the points (x, y, z in metres, intensity, gps_time, rgb, extras).
Usage: read_las.py FILE [MAX_POINTS]"""
import json
import struct
import sys

EXTRA_TYPES = {1: "B", 2: "b", 3: "H", 4: "h", 5: "I", 6: "i", 7: "Q", 8: "q", 9: "f", 10: "d"}


def read(path, max_points):
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] != b"LASF":
        raise SystemExit(f"{path}: not a LAS file")
    h = {}
    (h["file_source_id"], h["global_encoding"]) = struct.unpack_from("<HH", data, 4)
    h["version"] = f"{data[24]}.{data[25]}"
    h["system"] = data[26:58].rstrip(b"\0").decode()
    h["software"] = data[58:90].rstrip(b"\0").decode()
    (h["header_size"], h["offset_to_points"], n_vlr, h["point_format"],
     h["record_length"]) = struct.unpack_from("<HIIBH", data, 94)
    scale = struct.unpack_from("<3d", data, 131)
    offset = struct.unpack_from("<3d", data, 155)
    mx = struct.unpack_from("<6d", data, 179)  # max x, min x, max y, min y, max z, min z
    h["max"] = [mx[0], mx[2], mx[4]]
    h["min"] = [mx[1], mx[3], mx[5]]
    h["legacy_points"] = struct.unpack_from("<I", data, 107)[0]
    (h["points"],) = struct.unpack_from("<Q", data, 247)
    h["scale"], h["offset"] = list(scale), list(offset)
    at = h["header_size"]
    wkt, extras = None, []
    for _ in range(n_vlr):
        user = data[at + 2:at + 18].rstrip(b"\0").decode()
        record_id, length = struct.unpack_from("<HH", data, at + 18)
        body = data[at + 54:at + 54 + length]
        if user == "LASF_Projection" and record_id == 2112:
            wkt = body.rstrip(b"\0").decode()
        if user == "LASF_Spec" and record_id == 4:
            for d in range(0, length, 192):
                desc = body[d:d + 192]
                extras.append({"name": desc[4:36].rstrip(b"\0").decode(),
                               "type": desc[2],
                               "description": desc[160:192].rstrip(b"\0").decode()})
        at += 54 + length
    if h["point_format"] not in (6, 7, 8):
        raise SystemExit(f"{path}: point format {h['point_format']} not read here")
    base = {6: 30, 7: 36, 8: 38}[h["point_format"]]
    extra_fmt = "<" + "".join(EXTRA_TYPES[e["type"]] for e in extras)
    if base + struct.calcsize(extra_fmt) != h["record_length"]:
        raise SystemExit(f"{path}: record length {h['record_length']} does not match the fields")
    points = []
    n = h["points"] if max_points is None else min(h["points"], max_points)
    for i in range(n):
        r = h["offset_to_points"] + i * h["record_length"]
        X, Y, Z, intensity = struct.unpack_from("<iiiH", data, r)
        classification = data[r + 16]
        (gps_time,) = struct.unpack_from("<d", data, r + 22)
        p = {"x": X * scale[0] + offset[0], "y": Y * scale[1] + offset[1],
             "z": Z * scale[2] + offset[2], "intensity": intensity, "gps_time": gps_time,
             "classification": classification, "return_byte": data[r + 14]}
        if h["point_format"] >= 7:
            p["rgb"] = list(struct.unpack_from("<HHH", data, r + 30))
        values = struct.unpack_from(extra_fmt, data, r + base)
        p["extra"] = {e["name"]: v for e, v in zip(extras, values)}
        points.append(p)
    expected = h["offset_to_points"] + h["points"] * h["record_length"]
    if len(data) != expected:
        raise SystemExit(f"{path}: {len(data)} bytes, header says {expected}")
    return {"header": h, "wkt": wkt, "extra_fields": extras, "points": points}


if __name__ == "__main__":
    limit = int(sys.argv[2]) if len(sys.argv) > 2 else None
    print(json.dumps(read(sys.argv[1], limit)))
