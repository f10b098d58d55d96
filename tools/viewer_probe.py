#!/usr/bin/env python3
"""Probes a running live viewer (`macrotree run TREE --view`) the way a hostile local client
would, and prints what the server did. Standard library only; Linux (/proc).

usage: tools/viewer_probe.py PID PORT loris|bigframe

  loris     send a request head one byte per second; print when the server closes it
  bigframe  8 websocket clients each announce a 15 MiB frame and send its payload; print how
            much each could send and the server's resident memory before and after
"""
import socket
import sys
import threading
import time


def rss_mib(pid):
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    return 0.0


def upgrade(s, port):
    s.sendall(
        (
            f"GET / HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nOrigin: http://127.0.0.1:{port}\r\n"
            "Upgrade: websocket\r\nConnection: Upgrade\r\n"
            "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n"
        ).encode()
    )


def drain(s):
    try:
        while s.recv(1 << 16):
            pass
    except OSError:
        pass


def loris(port, give_up=60.0):
    s = socket.create_connection(("127.0.0.1", port))
    s.settimeout(1.0)
    t0 = time.time()
    head = b"GET / HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nX-Pad: " % port + b"a" * 1000
    for i, b in enumerate(head):
        try:
            s.send(bytes([b]))
            data = s.recv(100)
            print(f"closed after {time.time() - t0:.1f} s, {i + 1} bytes sent, answer {data[:30]!r}")
            return
        except socket.timeout:
            pass
        except OSError as e:
            print(f"closed after {time.time() - t0:.1f} s ({e})")
            return
        if time.time() - t0 > give_up:
            print(f"still open after {give_up:.0f} s")
            return


def bigframe(pid, port, clients=8, size=15 << 20):
    before = rss_mib(pid)
    conns, sent = [], []
    for _ in range(clients):
        s = socket.create_connection(("127.0.0.1", port))
        upgrade(s, port)
        threading.Thread(target=drain, args=(s,), daemon=True).start()
        # A binary frame, not final, masked, with a 64-bit length.
        s.sendall(bytes([0x02, 0xFF]) + size.to_bytes(8, "big") + b"\x01\x02\x03\x04")
        done, chunk = 0, b"\0" * (1 << 16)
        s.settimeout(5)
        try:
            while done < size:
                done += s.send(chunk[: size - done])
        except OSError:
            pass
        conns.append(s)
        sent.append(done)
    time.sleep(1)
    mib = [round(x / 2**20, 1) for x in sent]
    print(
        f"{clients} clients each announcing a {size >> 20} MiB frame sent {mib} MiB; "
        f"server RSS {before:.0f} -> {rss_mib(pid):.0f} MiB"
    )


if __name__ == "__main__":
    if len(sys.argv) != 4 or sys.argv[3] not in ("loris", "bigframe"):
        sys.exit(__doc__)
    pid, port, what = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
    loris(port) if what == "loris" else bigframe(pid, port)
