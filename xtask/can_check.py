"""The cantools side of `cargo xtask test`'s CAN check (xtask/checks/src/can_check.rs).

usage: can_check.py EHA.DBC FIRMWARE_FRAMES.JSON CANTOOLS_FRAMES.JSON

Reads the frames the firmware encoded, each with the raw values, physical values and
value-table names it was built from; decodes every frame with cantools and the DBC file and
compares value for value; encodes the same message with cantools from its physical values
and names and writes the bytes for the firmware's decoder; finally runs the README's
`python3 -m cantools decode --single-line` on candump lines. Any difference is an error
(exit 1) naming the frame and the signal.
"""

import json
import math
import subprocess
import sys

import cantools


def close(a, b):
    return math.isclose(a, b, rel_tol=1e-12, abs_tol=1e-12)


def check_frame(db, v, problems):
    frame_id, data = v["frame_id"], bytes.fromhex(v["data"])
    msg = db.get_message_by_frame_id(frame_id)
    where = f"{msg.name} {frame_id:03X}#{v['data'].upper()}"
    raw = msg.decode(data, decode_choices=False, scaling=False)
    physical = msg.decode(data, decode_choices=False)
    named = msg.decode(data, decode_choices=True)
    if set(raw) != set(v["raw"]):
        problems.append(f"{where}: signals {sorted(raw)}, expected {sorted(v['raw'])}")
        return None
    for name, want in v["raw"].items():
        if raw[name] != want:
            problems.append(f"{where}: {name} raw {raw[name]!r}, expected {want!r}")
    for name, want in v["physical"].items():
        if not close(physical[name], want):
            problems.append(f"{where}: {name} = {physical[name]!r}, expected {want!r}")
    for name, want in v["names"].items():
        if str(named[name]) != want:
            problems.append(f"{where}: {name} named {str(named[name])!r}, expected {want!r}")
    # The other way: cantools builds the frame from physical values and names.
    values = dict(v["physical"])
    values.update(v["names"])
    return msg.encode(values).hex()


def check_cli(dbc, problems):
    """The README's command on candump's output format."""
    lines = [
        "  can0  181   [8]  03 00 88 13 85 FF 11 07",
        "  can0  201   [5]  0A 00 00 80 3E",
        "  can0  191   [8]  20 02 00 00 20 41 0A 00",
    ]
    out = subprocess.run(
        [sys.executable, "-m", "cantools", "decode", "--single-line", dbc],
        input="\n".join(lines) + "\n",
        capture_output=True,
        text=True,
        check=False,
    )
    expected = [
        "Status(Mode: pressure, Fault: none, Pressure: 5000",
        "SetParameter(ParameterId: speed.kp, speed_kp: 0.25",
        "Reject(Function: SetParameter, Reason: above maximum, Bound_SetParameter: 10.0",
    ]
    for want in expected:
        if want not in out.stdout:
            problems.append(f"cantools decode: `{want}` not in:\n{out.stdout}{out.stderr}")


def main():
    dbc, frames_in, frames_out = sys.argv[1:4]
    db = cantools.database.load_file(dbc)
    with open(frames_in, encoding="utf-8") as f:
        vectors = json.load(f)
    problems = []
    encoded = []
    for v in vectors:
        try:
            encoded.append(check_frame(db, v, problems))
        except Exception as e:  # noqa: BLE001 - every failure is reported with its frame
            problems.append(f"{v['frame_id']:03X}#{v['data'].upper()}: {type(e).__name__}: {e}")
    check_cli(dbc, problems)
    if problems:
        for p in problems[:40]:
            print(p, file=sys.stderr)
        print(f"{len(problems)} differences between the DBC file and the firmware", file=sys.stderr)
        sys.exit(1)
    with open(frames_out, "w", encoding="utf-8") as f:
        json.dump(encoded, f)
    print(f"cantools {cantools.__version__}: {len(vectors)} frames decoded and encoded")


if __name__ == "__main__":
    main()
