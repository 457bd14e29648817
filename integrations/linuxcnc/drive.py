#!/usr/bin/python3
"""Drive a headless LinuxCNC (DISPLAY = linuxcncrsh) over 127.0.0.1:5007: machine on, home,
run one program to its end, report its errors, shut LinuxCNC down.
Usage: drive.py /abs/path/prog.ngc [settle_s]   (run by run-headless; /usr/bin/python3 only)"""
import socket, sys, time

PROG = sys.argv[1]
SETTLE_S = float(sys.argv[2]) if len(sys.argv) > 2 else 1.0
CONNECT_S, PROGRAM_S = 30.0, 600.0


def fail(msg):
    print("drive.py: " + msg, flush=True)
    sys.exit(1)


class Rsh:
    def __init__(self, port=5007):
        end = time.time() + CONNECT_S
        while True:
            try:
                self.s = socket.create_connection(("127.0.0.1", port), timeout=10)
                break
            except OSError:
                if time.time() > end:
                    fail(f"LinuxCNC did not start: linuxcncrsh on 127.0.0.1:{port} not reachable within {CONNECT_S:.0f} s")
                time.sleep(0.2)  # waiting for another process to listen; nothing to block on
        self.buf = b""

    def line(self):
        while True:
            for sep in (b"\r\n", b"\n\r"):  # linuxcncrsh ends 'set' replies with \n\r
                i = self.buf.find(sep)
                if i >= 0:
                    l, self.buf = self.buf[:i], self.buf[i + 2:]
                    if l.strip():
                        return l.decode().strip()
            d = self.s.recv(4096)
            if not d:
                fail("linuxcncrsh closed the connection (LinuxCNC stopped?)")
            self.buf += d

    def cmd(self, c):
        self.s.sendall((c + "\r\n").encode())
        return self.line()

    def ack(self, c):
        r = self.cmd(c)
        if "ACK" not in r or "NAK" in r:
            fail(f"'{c}' refused: {r}")


r = Rsh()
r.cmd("hello EMC eical-drive 1.0")
r.s.sendall(b"set echo off\r\n")
r.line()
for c in ["set verbose on", "set enable EMCTOO", "set estop off", "set machine on", "set mode manual", "set home -1"]:
    r.ack(c)
end = time.time() + 10
while r.cmd("get joint_homed").split()[1:4] != ["YES"] * 3:
    if time.time() > end:
        fail("joints not homed within 10 s")
    time.sleep(0.05)
r.ack("set mode auto")
r.ack("set open " + PROG)  # linuxcncrsh needs an absolute path
t_run = time.time()
r.ack("set run")
while r.cmd("get program_status") == "PROGRAM_STATUS IDLE" and time.time() - t_run < 2:
    time.sleep(0.005)
while r.cmd("get program_status") != "PROGRAM_STATUS IDLE":
    if time.time() - t_run > PROGRAM_S:
        fail(f"program still running after {PROGRAM_S:.0f} s")
    time.sleep(0.02)
print(f"drive.py: program ran {time.time() - t_run:.2f} s", flush=True)
err = r.cmd("get error")
time.sleep(SETTLE_S)  # eicald turns the last servo samples into frames meanwhile
r.s.sendall(b"shutdown\r\n")
if err.strip() not in ("ERROR", "ERROR OK") and "OK" not in err:
    fail("LinuxCNC reported: " + err)
