"""Every command's answer to a bad command line: exit code 2, one line on stderr that starts
``unstack: error:`` and says what was expected, and nothing written.

One table for all the commands, so that each refusal is held to the same rule; ``{tmp}`` is the
test's folder, ``{camera}`` a camera's files as ``unstack scene`` takes them and ``{detected}`` a
cloud with a detector's boxes (``tests/cli/conftest.py``).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.conftest import PILE5, unstack

pytestmark = pytest.mark.slow  # runs the CLI in subprocesses

SIMULATE = ["simulate", "--configs", "1", "--out", "{tmp}/out"]
SCENE = ["scene", "{camera}", "--out", "{tmp}/scene.json"]
DETECTED = ["scene", "{detected}", "--out", "{tmp}/scene.json"]
#: Placeholders of the table and the fixtures that give their arguments.
FILES = {"{camera}": "camera_files", "{detected}": "cloud_and_detections"}

#: Values of decide's options that are refused with the option named.
NAMED_BAD_VALUES = {
    "--samples": ("0",),
    "--time-limit": ("0", "nan", "inf", "-1"),
    "--method": ("fast",),
    "--seed": ("-1",),
    "--near-ties": ("nan", "-0.1", "inf"),
    "--free-cost": ("-0.5", "nan"),
}
REFUSALS = [
    *((["decide", PILE5, option, value], option) for option, values in NAMED_BAD_VALUES.items() for value in values),
    (["decide", PILE5, "--samples", "1000000000"], "samples must be at most 100,000,000"),
    (["decide", "missing.json"], "missing.json: $: no such file"),
    (["decide", "examples"], "examples: $: expected a JSON file, got a directory"),
    (["decide", PILE5, "--output", "{tmp}/no/such/dir/out.json"], "no/such/dir/out.json: cannot write there"),
    (["validate", "examples/scene3.json", "missing.json"], "missing.json: $: no such file"),
    (["validate", "-", "-"], "-: standard input can be read once; it is named twice"),
    (
        ["render", "-", "--decision", "-", "-o", "{tmp}/both.png"],
        "-: standard input can be read once; it is named for two",
    ),
    (
        ["evaluate", "general", "{tmp}", "--reliability", "{tmp}/rel.txt"],
        "--reliability: {tmp}/rel.txt: expected a .png",
    ),
    ([*SCENE, "--sizes", "0.4x0.3"], "--sizes: expected three edges"),
    ([*SCENE, "--ids", "a"], "--ids names 1 boxes but 2 masks"),
    ([*SCENE, "--depth-units", "m"], "declared in m but the median reading is"),
    ([*SCENE, "--depth-units", "0.1mm"], "'--depth-units': expected mm, m or the metres of one unit (1e-06 to 1;"),
    ([*SCENE, "--ids", "a,"], "--ids: expected 2 non-empty box ids separated by commas, got 'a,'"),
    ([*SCENE, "--sizes", ""], "--sizes: expected sizes like 0.4x0.3x0.3 separated by commas, got ''"),
    ([*SCENE, "--sizes", "0.4x0.3x0.3,"], "separated by commas, got '' in '0.4x0.3x0.3,'"),
    ([*SCENE, "--ids", "a," + "b" * 300], "--ids: expected an id of at most 200 characters, got one of 300 ('bbbb"),
    ([*SCENE, "--door", "0,0,1"], "within 15 degrees of the vertical"),
    ([*SCENE, "--sizes", "0.01x0.01x0.01"], "--sizes: expected three edges of 0.02-5 m per size, got '0.01x0.01x0.01'"),
    ([*DETECTED, "--sizes", "0.4x0.3x0.3", "--ids", "a,b"], "--sizes and --ids apply to mask files and a depth image"),
    ([*DETECTED, "--depth-units", "mm"], "--depth-units apply to mask files and a depth image"),
    ([*DETECTED, "--intrinsics", "{tmp}/k.json"], "--intrinsics: for a depth image, not for --cloud (a cloud takes"),
    (["train", "{tmp}", "-o", "{tmp}/m.skops", "--seed", "4294967296"], "seed must be at most 4,294,967,295"),
    (
        ["experiment", "fig5a", "{tmp}", "--out", "{tmp}/r", "--seed", "4294967296"],
        "seed must be at most 4,294,967,295",
    ),
    ([*SIMULATE, "--sizes", "paper3"], "'paper3' is not one of 'paper2', 'four', 'mixed'"),
    ([*SIMULATE, "--boxes", "40-30"], "--boxes: the range 40-30 is reversed"),
    ([*SIMULATE, "--boxes", "many"], "--boxes: expected COUNT or LOW-HIGH (for example 30-40), got 'many'"),
    ([*SIMULATE, "--boxes", "500-600"], "600 boxes of size set 'paper2' do not fit"),
    ([*SIMULATE, "--configs", "-3"], "Invalid value for '--configs': -3 is not in the range 1<=x<=100000"),
    ([*SIMULATE, "--configs", "10000000000"], "'--configs': 10000000000 is not in the range 1<=x<=100000"),
    ([*SIMULATE, "--jobs", "0"], "Invalid value for '--jobs': 0 is not in the range 1<=x<=256"),
    ([*SIMULATE, "--min-pixels", "0"], "'--min-pixels': expected a number at least 1, got 0"),
    (
        [*SIMULATE, "--resolution", "96x72", "--min-pixels", "100000"],
        "settings.sensor.min_pixels: expected at most the image's 6,912 pixels (96 x 72): no box could be detected",
    ),
    ([*SIMULATE, "--boxes", "1"], "--boxes: expected at least 2 boxes a pile (one box supports nothing), got '1'"),
    ([*SIMULATE, "--resolution", "big"], "--resolution: expected WIDTHxHEIGHT in pixels"),
    ([*SIMULATE, "--width", "0"], "'--width': expected a positive extent of at most 100 m, got 0.0"),
    ([*SIMULATE, "--boxes", "9", "--sizes", "four", "--depth", "0.6", "--width", "0.8"], "do not fit a 0.6 x 0.8"),
    ([*SIMULATE, "--scheduler", "tcp://127.0.0.1:9"], "dask scheduler tcp://127.0.0.1:9 does not answer within 5 s"),
    ([*SIMULATE, "--scheduler", "nowhere"], "'--scheduler': expected an address like tcp://HOST:PORT, got 'nowhere'"),
    (
        [*SIMULATE, "--scheduler", "tls://127.0.0.1:8786"],
        "'--scheduler': tls:// needs dask's security settings",
    ),
    ([*SIMULATE, "--scheduler", ""], "'--scheduler': expected an address like tcp://HOST:PORT, got ''"),
    ([*SIMULATE, "--jobs", "2", "--scheduler", "tcp://127.0.0.1:9"], "jobs: 2 local processes and a scheduler exclude"),
]


@pytest.mark.parametrize(
    ("arguments", "message"), REFUSALS, ids=[f"{row[0][0]} {' '.join(row[0][-2:])}" for row in REFUSALS]
)
def test_a_bad_command_line_is_refused_in_one_line_with_nothing_written(
    request: pytest.FixtureRequest, tmp_path: Path, arguments: list[str], message: str
) -> None:
    given = {name: request.getfixturevalue(fixture) for name, fixture in FILES.items() if name in arguments}
    expanded = [part for argument in arguments for part in given.get(argument, [argument])]
    before = sorted(tmp_path.rglob("*"))
    result = unstack(*[argument.format(tmp=tmp_path) for argument in expanded])
    assert result.returncode == 2, result.stderr
    assert result.stderr.startswith("unstack: error: ") and result.stderr.count("\n") == 1, result.stderr
    assert message.format(tmp=tmp_path) in result.stderr and "Traceback" not in result.stderr
    assert sorted(tmp_path.rglob("*")) == before
