"""``gige://`` URLs: settings parsed, mistakes refused in one line naming the part (parsing
sends nothing: no camera is opened here)."""

from __future__ import annotations

import pytest

from cell.camera.errors import CameraError
from cell.camera.gige_url import parse_gige_url
from cell.camera.open import open_camera
from measure.synth import standard_stereo


def test_settings_and_defaults() -> None:
    o = parse_gige_url("gige://192.168.10.11,192.168.10.12?trigger=Line0&packet_size=9000"
                       "&resend=0&exposure_us=800&pair_ms=2")  # fmt: skip
    assert (o.left_ip, o.right_ip, o.trigger, o.packet_size) == (
        "192.168.10.11", "192.168.10.12", "line0", 9000)  # fmt: skip
    assert not o.resend and o.exposure_us == 800.0 and o.pair_bound_ns == 2_000_000
    d = parse_gige_url("gige://127.0.0.1,127.0.0.2")
    assert d.trigger == "software" and d.packet_size == 1500 and d.pair_bound_ns == 250_000_000
    assert parse_gige_url("gige://127.0.0.1,127.0.0.2?packet_size=auto").packet_size is None
    assert parse_gige_url("gige://127.0.0.1,127.0.0.2?trigger=line1").pair_bound_ns == 1_000_000


@pytest.mark.parametrize(
    ("url", "says"),
    [("gige://127.0.0.1", "give two camera addresses"),
     ("gige://cam-left,127.0.0.2", "'cam-left' is not an IPv4 address"),
     ("gige://127.0.0.1,127.0.0.1", "the same address"),
     ("gige://127.0.0.1,127.0.0.2?packet_size=100", "packet_size='100': 576..16384"),
     ("gige://127.0.0.1,127.0.0.2?trigger=line9", "trigger='line9': one of software"),
     ("gige://127.0.0.1,127.0.0.2?timeout_ms=nan", "timeout_ms='nan'"),
     ("gige://127.0.0.1,127.0.0.2?fps=5", "unknown setting 'fps'")],
)  # fmt: skip
def test_mistakes_are_one_line(url: str, says: str) -> None:
    with pytest.raises(CameraError) as err:
        parse_gige_url(url)
    assert says in str(err.value) and "\n" not in str(err.value)


def test_an_unknown_scheme_is_refused() -> None:
    with pytest.raises(CameraError, match="expected tcp:// or gige://"):
        open_camera("usb3://1,2", standard_stereo())


def test_holecell_run_refuses_a_bad_camera_url_before_connecting(capsys) -> None:
    from cell.cli import main

    code = main(["run", "tour.json", "--cell", "cell.yaml", "--port", "/dev/null/none",
                 "--camera", "gige://left-cam,right-cam"])  # fmt: skip
    err = capsys.readouterr().err
    assert code == 2 and "'left-cam' is not an IPv4 address" in err
