#!/usr/bin/env python3
"""Writes the committed seed corpus of every fuzz target into fuzz/corpus/<target>/.

Seeds are small valid inputs taken from config/, tests/data and what eical itself
writes (when EICAL is given: gen-nc programs, simulate --export captures, a sensor
calibration), plus a few broken ones. Run from the repository:
    fuzz/seed_corpus.py [EICAL_BINARY]
Inputs the fuzzers found later (findings' regression inputs) are added by hand beside
these, named finding-*; this script never deletes them.
"""
import gzip
import os
import pathlib
import struct
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
SHARED = ROOT / "tests" / "data"
CORPUS = ROOT / "fuzz" / "corpus"
EICAL = sys.argv[1] if len(sys.argv) > 1 else None


def put(target, name, data):
    d = CORPUS / target
    d.mkdir(parents=True, exist_ok=True)
    if isinstance(data, str):
        data = data.encode()
    (d / name).write_bytes(data)


def head_lines(text, n):
    return "".join(text.splitlines(keepends=True)[:n])


def eical(*args, cwd=None):
    subprocess.run([EICAL, *args], check=True, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


# --- run directory: run.toml, "\n%%samples\n", samples (plain or gzip), "\n%%truth\n", truth.toml
runs = sorted(SHARED.glob("*/run.toml"))[:6] + [SHARED / "independent" / r / "run.toml" for r in
                                                  ("baseline.rectangle-0012", "sensor.bias_drift-0012")]
for i, toml_path in enumerate(runs):
    run = toml_path.parent
    toml = toml_path.read_text()
    samples = head_lines(gzip.decompress((run / "samples.csv.gz").read_bytes()).decode(), 12)
    name = run.name
    put("run_dir", f"{name}", toml + "\n%%samples\n" + samples)
    if i == 0:
        put("run_dir", f"{name}-gz", toml.encode() + b"\n%%samples\n" + gzip.compress(samples.encode(), mtime=0))
        truth = (run / "truth.toml").read_text() if (run / "truth.toml").exists() else ""
        put("run_dir", f"{name}-truth", toml + "\n%%samples\n" + samples + "\n%%truth\n" + truth)
        lines = samples.splitlines(keepends=True)
        put("run_dir", "broken-truncated-gz", toml.encode() + b"\n%%samples\n" + gzip.compress(samples.encode(), mtime=0)[:-9])
        put("run_dir", "broken-time-back", toml + "\n%%samples\n" + lines[0] + lines[2] + lines[1])
        put("run_dir", "broken-missing-column", toml + "\n%%samples\n" + lines[0].replace(",trigger", "") + lines[1])
        put("run_dir", "broken-no-samples", toml)
        put("run_dir", "gap-and-empty-fields", toml + "\n%%samples\n" + lines[0] + lines[1] + lines[3].replace(",21.5", ",", 1))

# --- daemon config, scenarios, volumetric model
put("daemon_config", "eicald.toml", (ROOT / "config/eicald.toml").read_text())
put("daemon_config", "minimal", "[source]\nkind = \"sim\"\n")
put("daemon_config", "fault-and-triggers",
    "[source]\nkind = \"sim\"\npacing = \"free_running\"\n[source.fault]\ngap_at_s = 1.0\ngap_frames = 3\n"
    "[triggers]\ninputs = [\"frame\", \"gpio\"]\ngpio_lines = [17, 27, 22]\ncan_id = 0x1E0\n[limits]\nring_capacity_frames = 4096\n")
put("daemon_config", "broken-unknown-key", "[dds]\ndomain_idd = 3\n")
for p in sorted((ROOT / "config/scenarios").glob("*.toml")):
    put("scenario", p.stem, p.read_text())
put("scenario", "broken-effect", "format = \"eical-scenario/1\"\n[effects.\"machine.nonsense\"]\nx = 1\n")
put("volumetric_model", "example", (ROOT / "config/examples/volumetric-example.toml").read_text())
put("volumetric_model", "broken-component", "format = \"eical-volumetric/1\"\n[axes]\nx_range_mm = [0, 1]\ny_range_mm = [0, 1]\n"
    "z_range_mm = [0, 1]\n[squareness]\nxwy = 0\nxwz = 0\nywz = 0\n[[component]]\nname = \"xtq\"\npositions_mm = [0]\nvalues = [0]\n")

# --- sensor calibration (eical-sensor-cal/1)
put("sensor_calibration", "datasheet-delay",
    "format = \"eical-sensor-cal/1\"\nmethod = \"psd\"\nrun = \"identify-0001\"\n[acquisition]\ndaq_group_delay_samples = 38.93\n"
    "daq_skew_head_samples = 0.9\n")
put("sensor_calibration", "full",
    "format = \"eical-sensor-cal/1\"\nmethod = \"ref\"\nrun = \"r\"\n[sensors.table]\nk1_v_per_g = [1.2391, 1.2263, 1.2307]\n"
    "bias_g = [0.044, 0.01, -0.012]\nf0_hz = 1000.0\nzeta = 0.707\nto_machine = [[1, -0.0031, 0], [0, 1, 0], [0, 0, 1]]\n"
    "cross_g_per_g = [[0, 0, 0], [0, 0, 0], [0.0021, 0, 0]]\n[sensors.head]\nf0_hz = 943.5\nzeta = 0.612\nzeta_per_g = 0.9\n")
put("sensor_calibration", "broken-skew", "format = \"eical-sensor-cal/1\"\n[acquisition]\ndaq_skew_head_samples = 1e9\n")

# --- G-code: the sample runs' programs (and gen-nc's dialects below)
for toml_path in runs:
    text = toml_path.read_text()
    if 'gcode = """' in text:
        put("gcode", toml_path.parent.name + ".ngc", text.split('gcode = """', 1)[1].split('"""', 1)[0])
put("gcode", "arcs-r-and-planes.ngc", "%\nO1234 (test)\nG21 G90 G18\nG0 X0 Y0 Z0\nG2 X10 Z10 R10 F1000\nG19 G3 Y5 Z5 J2.5 K0\n"
    "G17 G91 G1 X-1 Y1 F500\nG4 P0.5\nM101 P2 Q3\n/M3 S1000\nN10 M102 ; comment\nM103\nM30\n%\n")
put("gcode", "broken-canned-cycle.ngc", "G21 G90\nG81 X1 Y1 Z-1 R1 F100\n")
# Each control's own syntax (sim/gcode/parser.hpp, words.hpp), and a program of another.
put("gcode_fanuc", "dwells-units-comments.nc", "%\nO0001 (DWELLS)\nN10 G90 G21 G17 G61\nN20 G0 X0. Y0.\n"
    "N30 G04 P250\nN40 G04 X0.5\nN50 G1 X10. F1000 ; END OF BLOCK\nN60 G3 X0. Y10. R10. \nN70 G20 G1 X1. F10.\n"
    "M101 P1 Q2\nM30\n%\n")
put("gcode_fanuc", "broken-seconds-in-p.nc", "G04 P0.5\nG0 X10\n")
put("gcode_sinumerik", "dwells-units-comments.mpf", "%_N_SEED_MPF\n;$PATH=/_N_MPF_DIR\nN10 G90 G710 G17 G60\n"
    "N20 G0 X0 Y0\nN30 S1000 M3\nN40 G4 S5\nN50 G4 F0.25\nN60 G70 G1 X1 F500\nN70 G700 G2 X0 Y1 I-1 J0 F20\n"
    "N80 G71 G64 G18 G3 Z1 X0 K0 I1\nM5\nM30\n")
put("gcode_sinumerik", "broken-linuxcnc-dwell.mpf", "G71\nG4 P400\nG0 X1 (comment)\n")
put("gcode_heidenhain_iso", "centre-radius-dwell.h", "%SEED G71 *\nN10 G90 G17 *\nN20 G00 X+10 Y+0 *\n"
    "N30 G04 F0.5 *\nN40 I+0 J+0 *\nN50 G03 X+0 Y+10 F1000 *\nN60 G02 X+10 Y+0 R+10 * ; r form\n"
    "N70 G91 I+0 J-10 G02 X+0 Y+0 *\nN80 G90 G18 K+0 I+0 G03 Z+10 X+0 *\nN99999999 %SEED G71 *\n")
put("gcode_heidenhain_iso", "broken-after-block-end.h", "%SEED G70 *\nN10 G00 X+1 * Y+2\n")

# --- CSV tables of the command line
put("deviation_csv", "two-runs", "target_mm,run,direction,deviation_um\n" + "".join(
    f"{t},{r},{d},{0.1 * t + r - (d == 'down')}\n" for t in (0, 10, 20) for r in (1, 2) for d in ("up", "down")))
put("deviation_csv", "broken-direction", "target_mm,run,direction,deviation_um\n0,1,up,1\n0,1,sideways,1\n")
for p in sorted((SHARED / "external/iso230-2").glob("*.dat")):
    put("ecmc_dat", p.stem, p.read_text())
put("ecmc_dat", "broken-index", "TGT_DATA[1]=1\nREF_DATA_FWD[1]=1\n")
put("curve_csv", "linear", "pos_mm,error_um\n0,0\n50,1\n100,2\n150,2.5\n200,4\n")
put("curve_csv", "comments-spaces", "# lead error\npos_mm, error_um, ext_note\n0, 0.5, a\n100, -1, b\n300, 2, c\n")
put("curve_csv", "broken-duplicate", "pos_mm,error_um\n0,1\n10,2\n10,3\n20,4\n")
put("series_csv", "two-series", "angle_deg,deviation_arcsec,series\n" + "".join(
    f"{s * 7.5 + k * 30},{(k % 3) - 1 + 0.1 * s},{'ABC'[s]}\n" for s in range(3) for k in range(12)))
put("series_csv", "broken-nan", "angle_deg,deviation_arcsec,series\n0,nan,a\n")
put("points_csv", "inside-and-out", "x,y,z,xp,yp,zp\n0,0,0,0,0,0\n400,250,200,0,0,100\n-1,0,0,0,0,0\n0,0,401,0,0,0\n")
put("points_csv", "broken-fields", "x,y,z,xp,yp,zp\n1,2,3\n")

# --- importers
put("klipper_capture", "current", "#time,accel_x,accel_y,accel_z\n" + "".join(
    f"{100.0 + k / 3200:.6f},{(k % 7) * 10.0:.6f},{-(k % 5) * 3.0:.6f},9806.650000\n" for k in range(40)))
put("klipper_capture", "legacy-stats", "##<stats>\n#time,accel_x,accel_y,accel_z\n" + "".join(
    f"{5.0 + k / 1600:.6f},{k:.6f},0.000000,{-k:.6f}\n" for k in range(10)))
put("klipper_capture", "broken-header", "time,x,y,z\n0,0,0,0\n")


def zstd_raw_frames(data, block=200):
    """zstd frames holding `data` as raw (stored) blocks, RFC 8878 3.1.1: no zstd module needed."""
    out = b""
    for i in range(0, max(len(data), 1), 255):
        part = data[i:i + 255]
        out += b"\x28\xb5\x2f\xfd\x20" + bytes([len(part)])
        out += struct.pack("<I", 1 | (len(part) << 3))[:3] + part
    return out


put("shaketune_stdata", "one-measurement", zstd_raw_frames(
    b'{"name": "axis_x_20261207", "samples": [' +
    b", ".join(b"[%.6f, %.3f, %.3f, %.3f]" % (100 + i / 400, 10 * i, -5.0, 9806.65) for i in range(12)) + b"]}\n"))
put("shaketune_stdata", "two-belts", zstd_raw_frames(
    b'{"name": "belt_a", "samples": [[1.0, 1, 2, 9806], [1.0025, 3, 4, 9807]]}\n'
    b'{"name": "belt_b", "samples": [[9.0, 1, 2, 9806], [9.0025, 3, 4, 9807], [9.005, 0, 0, 9806]]}\n'))
put("shaketune_stdata", "pickled", zstd_raw_frames(b"\x80\x04\x95\x10\x00\x00\x00]\x94}\x94."))
put("accel_csv", "by-position", b"\x00" + b"t,ax,ay,az\n" + "".join(
    f"{k * 0.0005:.9f},{k % 3},0.1,-9.8\n" for k in range(30)).encode())
put("accel_csv", "by-name-g-ms", b"\x0b" + b"ax,t,az,ay,ext_extra\n" + "".join(
    f"{k % 3},{k * 0.5 + (0.3 if k == 20 else 0)},1,0,x\n" for k in range(30)).encode())
put("accel_csv", "broken-time", b"\x00t,ax,ay,az\n0,0,0,0\n0,0,0,0\n")
put("halsampler", "with-overrun", "".join(f"{n} {n * 0.01:f} 0.000000 1.000000 {n * 0.01:f} 0.000000 1.000000 {101 if n == 3 else 0}\n"
                                          for n in range(10)) + "overrun\n" + "".join(
    f"{n} {n * 0.01:f} 0.000000 1.000000 {n * 0.01:f} 0.000000 1.000000 0\n" for n in range(14, 30)))
put("halsampler", "broken-columns", "0 1 2 3\n")
put("nc_csv", "by-position", b"\x00t,x,y,z\n" + "".join(f"{k * 0.001:.9f},{k * 0.01:.9f},0,5\n" for k in range(30)).encode())
put("nc_csv", "by-name-us", b"\x05z,x,y,t\n" + "".join(f"5,{k * 0.01:.6f},0,{k * 1000}\n" for k in range(30)).encode())
put("nc_csv", "broken-blank-inside", b"\x00t,x,y,z\n0,0,0,0\n\n1,1,1,1\n")


# --- usb_daq: byte 0 = PSD strips expected (0..4) + chunking, then PROTOCOL.md packets
def crc16(data, crc=0xFFFF):
    for b in data:
        crc ^= b << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1021 if crc & 0x8000 else crc << 1) & 0xFFFF
    return crc


def packet(kind, channels, samples, seq, payload):
    body = bytes([1, kind, channels, samples]) + struct.pack("<I", seq) + payload
    return b"\xea\x1c" + body + struct.pack("<H", crc16(body))


def samples_packet(seq, n, channels, status=0):
    payload = b""
    for k in range(n):
        payload += bytes([status])
        for c in range(channels):
            payload += ((((seq + k) % 4096) * 1000 + c * 7 - 5000) & 0xFFFFFF).to_bytes(3, "little")
    return packet(1, channels, n, seq, payload)


def slow_packet(seq, t0, t1, trigger):
    return packet(2, 0, 1, seq, struct.pack("<hhB", round(t0 * 100), round(t1 * 100), trigger))


put("usb_daq", "two-psd", bytes([2]) + slow_packet(0, 21.5, 22.25, 101) + samples_packet(0, 8, 10) + samples_packet(8, 8, 10))
put("usb_daq", "gap-and-garbage", bytes([0]) + samples_packet(100, 4, 6) + b"\x00\xea\x13junk" + samples_packet(110, 4, 6, 1)
    + samples_packet(2**32 - 2, 4, 6))
put("usb_daq", "broken-crc", bytes([1]) + samples_packet(0, 2, 8)[:-1] + b"\x00" + samples_packet(2, 2, 8))
# One bulk transfer as UsbDaqSource reads it (16 KiB, 64-sample packets back to back).
stream, seq = b"", 0
while len(stream) < 16384 - 600:
    stream += samples_packet(seq, 64, 8)
    seq += 64
put("usb_daq", "full-transfer", bytes([1]) + stream)


# --- CAN trigger frame: struct can_frame (id, len, 3 pad bytes, data[8])
def can_frame(can_id, data, length=8):
    return struct.pack("<IB3x", can_id, length) + bytes(data).ljust(8, b"\x00")


put("can_trigger", "m101", can_frame(0x1E0, [1, 0, 0, 0, 0, 0x80]))
put("can_trigger", "m102-p2500", can_frame(0x1E0, [2, 7] + list(struct.pack("<i", 2500000))))
put("can_trigger", "broken-other-id", can_frame(0x1E1, [3, 1]))
put("can_trigger", "broken-short", can_frame(0x1E0, [3, 1], length=2))


# --- DDS Command: encapsulation header + CDR of eical::msg::Command (sender, request_id,
# action, code, p, q, time_ns)
def cdr_command(sender, request_id, action, code, p, q, t_ns, big=False, xcdr2=False):
    e = ">" if big else "<"
    out = bytearray()

    def align(n):
        n = min(n, 4) if xcdr2 else n
        while len(out) % n:
            out.append(0)

    def string(s):
        align(4)
        b = s.encode() + b"\x00"
        out.extend(struct.pack(e + "I", len(b)) + b)

    string(sender)
    align(4); out.extend(struct.pack(e + "I", request_id))
    string(action)
    align(4); out.extend(struct.pack(e + "i", code))
    for v in (p, q):
        align(8); out.extend(struct.pack(e + "d", v))
    align(8); out.extend(struct.pack(e + "q", t_ns))
    ident = (0x0006 if big else 0x0007) if xcdr2 else (0x0000 if big else 0x0001)
    return struct.pack(">HH", ident, 0) + bytes(out)


nan = float("nan")
put("dds_command", "trigger-101", cdr_command("eical-trigger-42", 1, "trigger", 101, nan, nan, 123456789))
put("dds_command", "trigger-102-pq-be", cdr_command("hmi", 7, "trigger", 102, 2.0, 3.0, 5, big=True))
put("dds_command", "arm-xcdr2", cdr_command("hmi", 9, "arm", 0, nan, nan, -1, xcdr2=True))
put("dds_command", "broken-string-length", cdr_command("x", 1, "trigger", 103, nan, nan, 0)[:4] + b"\xff\xff\xff\x7fabc")

# --- what eical itself writes (gen-nc dialects, an exported Klipper capture)
if EICAL:
    with tempfile.TemporaryDirectory() as tmp:
        for prog, extra in (("circle", ["--direction", "both"]), ("positioning", ["--targets", "0,50,100"]), ("step", ["--targets", "0,10"]), ("rectangle", []),
                            ("identify", ["--psd", "x:0,-10", "--psd", "y:10,0"])):
            for dialect in ("linuxcnc", "fanuc", "sinumerik", "heidenhain-iso"):
                out = os.path.join(tmp, f"{prog}-{dialect}.ngc")
                try:
                    eical("gen-nc", prog, *extra, "--dialect", dialect, "-o", out)
                except subprocess.CalledProcessError:
                    continue
                target = "gcode" if dialect == "linuxcnc" else "gcode_" + dialect.replace("-", "_")
                put(target, f"gen-nc-{prog}-{dialect}.ngc", pathlib.Path(out).read_text())
print("seed corpus written to", CORPUS)
