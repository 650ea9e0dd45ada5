"""Setting a real link up: key files, addresses beyond loopback, ports in use, hosts that do not resolve,
limits that are no limits, and configs recorded before the link's newer fields."""

from __future__ import annotations

import os
import socket

import pytest

from cerebx.config import load as load_plain
from cerebx.errors import CerebxError, ConfigError
from cerebx.link.auth import KEY_FILE_ENV, MAX_KEY_FILE_BYTES, key_from_env
from cerebx.link.transport import free_port, resolve
from cerebx.link.udp import UdpTransport
from cerebx.loop.resume import _check_same
from cerebx.schema.legacy import upgrade

UDP = ["+task=circle", "controller=pd", "link=udp", "clock=wall"]


def key_file(tmp_path, mode=0o600, text="ab" * 32):
    f = tmp_path / "link.key"
    f.write_text(text)
    f.chmod(mode)
    return f


def test_a_key_file_must_be_a_small_regular_file(tmp_path, capsys):
    assert key_from_env({KEY_FILE_ENV: str(key_file(tmp_path))}) is not None
    assert capsys.readouterr().err == ""
    with pytest.raises(CerebxError, match="not a regular file"):
        key_from_env({KEY_FILE_ENV: "/dev/zero"})
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    with pytest.raises(CerebxError, match="not a regular file"):  # and does not wait for a writer
        key_from_env({KEY_FILE_ENV: str(fifo)})
    with pytest.raises(CerebxError, match="not a regular file"):
        key_from_env({KEY_FILE_ENV: str(tmp_path)})
    big = tmp_path / "big.key"
    big.write_bytes(b"a" * (MAX_KEY_FILE_BYTES + 1))
    with pytest.raises(CerebxError, match=f"at most {MAX_KEY_FILE_BYTES}"):
        key_from_env({KEY_FILE_ENV: str(big)})


def test_a_key_file_others_may_read_gets_a_warning(tmp_path, capsys):
    assert key_from_env({KEY_FILE_ENV: str(key_file(tmp_path, 0o644))}) is not None
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "others may read it (mode 0644); chmod 600" in err[0]
    assert "ab" * 8 not in err[0]


def test_limits_must_be_finite(load):
    for field in ("link_lost_after_ms", "hold_pose_after_ms", "sensor_timeout_ms", "pair_timeout_s"):
        with pytest.raises(ConfigError, match="not a finite number"):
            load(UDP + [f"link.{field}=inf", "link.link_lost_after_ms=1e300" if field != "link_lost_after_ms"
                        else "link.hold_pose_after_ms=500"])


def test_addresses_beyond_loopback_need_the_opt_in(load, capsys):
    for address in ("0.0.0.0:7000", "'[::]:7000'", "192.168.1.5:7000", "robot.example:7000"):
        with pytest.raises(ConfigError, match="beyond the loopback interface"):
            load(UDP + [f"link.robot={address}"])
    assert load(UDP + ["link.robot=localhost:7000", "link.brain='[::1]:7001'"]).link.robot == "localhost:7000"
    cfg = load(UDP + [f"link.robot=0.0.0.0:{free_port('127.0.0.1', socket.SOCK_DGRAM)}", "link.beyond_loopback=true"])
    t = UdpTransport(cfg.link, "robot", False)
    t.close()
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert line.startswith("warning: link: the robot side listens on every interface")


def test_a_port_in_use_and_a_host_that_does_not_resolve_are_one_line(load):
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as taken:
        taken.bind(("127.0.0.1", 0))
        port = taken.getsockname()[1]
        cfg = load(UDP + [f"link.robot=127.0.0.1:{port}"])
        with pytest.raises(CerebxError) as err:
            UdpTransport(cfg.link, "robot", False)
    assert str(err.value) == f"link: udp cannot listen on 127.0.0.1:{port} (Address already in use)"
    with pytest.raises(CerebxError, match=r"^link: nowhere\.invalid:7000: the host cannot be resolved") as err:
        resolve("nowhere.invalid:7000")
    assert "\n" not in str(err.value)


def test_a_zenoh_port_in_use_is_one_line(load):
    pytest.importorskip("zenoh")
    from cerebx.link.zenoh_link import ZenohTransport

    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        cfg = load(["+task=circle", "controller=pd", "link=zenoh", "clock=wall", f"link.robot=127.0.0.1:{port}"])
        with pytest.raises(CerebxError, match=rf"^link: zenoh cannot listen on tcp/127.0.0.1:{port}") as err:
            ZenohTransport(cfg.link, "robot", False)
    assert "\n" not in str(err.value)


def test_zenoh_tls_reaches_zenohs_config(load):
    from cerebx.link.zenoh_link import tls_settings

    cfg = load(["+task=circle", "controller=pd", "link=zenoh", "clock=wall", "+link.tls.root_ca_certificate=ca.pem",
                "+link.tls.listen_certificate=me.pem", "+link.tls.listen_private_key=me.key"])
    assert tls_settings(cfg.link.tls) == {
        "root_ca_certificate": "ca.pem", "listen_certificate": "me.pem", "listen_private_key": "me.key",
        "connect_certificate": "me.pem", "connect_private_key": "me.key", "enable_mtls": True,
        "verify_name_on_connect": True}


@pytest.mark.parametrize("kind", ["udp", "zenoh"])
def test_a_link_recorded_before_its_newer_fields_is_the_same_config(kind):
    """A real-link run recorded before beyond_loopback, max_clock_uncertainty_ms (and zenoh's tls) existed is
    judged the same experiment as today's composition of its overrides."""
    overrides = ["+task=circle", "controller=pd", f"link={kind}", "clock=wall", "trials=2"]
    _, today = load_plain(overrides)
    old = {**today, "link": {k: v for k, v in today["link"].items()
                             if k not in ("beyond_loopback", "max_clock_uncertainty_ms", "tls")}}
    _check_same(upgrade(old), upgrade(today))
    far = {**old, "link": {**old["link"], "robot": "192.168.1.5:7447"}}
    assert upgrade(far)["link"]["beyond_loopback"] is True  # what that recorded run needed
    with pytest.raises(ConfigError):
        _check_same(upgrade({**old, "link": {**old["link"], "pings": 3}}), upgrade(today))
