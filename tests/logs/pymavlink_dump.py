"""Read a tlog with pymavlink in its own process (MAVLink 2 must be chosen before import).

Prints a JSON digest: message count, types seen, a hash of (type, timestamp, bytes) in order,
and a hash of the timestamps alone (µs) to compare with a tlog parsed without pymavlink.
"""

from __future__ import annotations

import hashlib
import json
import os
import sys


def main(path: str) -> None:
    """Digest every message pymavlink decodes from `path`."""
    os.environ["MAVLINK20"] = "1"
    from pymavlink import mavutil

    conn = mavutil.mavlink_connection(path, dialect="ardupilotmega")
    digest = hashlib.sha256()
    types: set[str] = set()
    stamps = hashlib.sha256()
    n = 0
    while True:
        msg = conn.recv_match()
        if msg is None:
            break
        n += 1
        types.add(msg.get_type())
        digest.update(f"{msg.get_type()}|{msg._timestamp:.6f}|".encode())
        digest.update(bytes(msg.get_msgbuf()))
        stamps.update(f"{round(msg._timestamp * 1e6)}|".encode())
    conn.close()
    result = {"count": n, "types": sorted(types), "sha256": digest.hexdigest(),
              "stamps_sha256": stamps.hexdigest()}
    print(json.dumps(result))


if __name__ == "__main__":
    main(sys.argv[1])
