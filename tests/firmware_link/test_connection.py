"""Connection strings: the forms ground stations use, and one-line errors for the rest."""

from __future__ import annotations

import pytest

from firmware_link import LinkError, LinkUsageError, Transport, parse_connection_string


@pytest.mark.parametrize(
    ("url", "transport", "host", "port", "device", "baud"),
    [
        ("/dev/ttyUSB0", Transport.SERIAL, "", 0, "/dev/ttyUSB0", 115200),
        ("/dev/ttyACM1,57600", Transport.SERIAL, "", 0, "/dev/ttyACM1", 57600),
        ("udpin:0.0.0.0:14550", Transport.UDPIN, "0.0.0.0", 14550, "", 115200),
        ("udpout:192.168.4.1:14555", Transport.UDPOUT, "192.168.4.1", 14555, "", 115200),
        ("tcp:127.0.0.1:5760", Transport.TCP, "127.0.0.1", 5760, "", 115200),
        ("  tcp:localhost:5762 ", Transport.TCP, "localhost", 5762, "", 115200),
    ],
)
def test_good_strings_parse(url, transport, host, port, device, baud) -> None:
    spec = parse_connection_string(url)
    assert (spec.transport, spec.host, spec.port, spec.device, spec.baud) == (
        transport,
        host,
        port,
        device,
        baud,
    )


@pytest.mark.parametrize(
    ("url", "fragment"),
    [
        ("", "empty"),
        ("tcp:127.0.0.1", "HOST:PORT"),
        ("tcp:127.0.0.1:abc", "not a number"),
        ("tcp:127.0.0.1:70000", "outside 0..65535"),
        ("tcp:127.0.0.1:0", "port 0"),
        ("udpout::14550", "HOST:PORT"),
        ("/dev/ttyUSB0,fast", "not a number"),
        ("/dev/ttyUSB0,12345", "not one of"),
        ("serial:/dev/ttyUSB0", "not understood"),
        ("http://vehicle", "not understood"),
        ("/dev/", "no serial device"),
    ],
)
def test_bad_strings_are_one_line_usage_errors(url: str, fragment: str) -> None:
    with pytest.raises(LinkUsageError) as info:
        parse_connection_string(url)
    message = str(info.value)
    assert fragment in message
    assert "\n" not in message
    assert info.value.exit_code == 2
    assert isinstance(info.value, LinkError)


def test_serial_capacity_is_baud_over_ten_and_network_is_unlimited() -> None:
    assert parse_connection_string("/dev/ttyUSB0").capacity_bytes_per_s == pytest.approx(11520)
    assert parse_connection_string("/dev/ttyUSB0,57600").capacity_bytes_per_s == 5760
    assert parse_connection_string("tcp:127.0.0.1:5760").capacity_bytes_per_s is None
    assert parse_connection_string("udpin:0.0.0.0:14550").reconnectable is False
    assert parse_connection_string("tcp:127.0.0.1:5760").reconnectable is True
