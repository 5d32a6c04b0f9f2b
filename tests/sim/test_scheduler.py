"""Reaching a dask scheduler: addresses checked before any connection, a one-line error in
seconds when nothing answers or something else does, never a hang."""

from __future__ import annotations

import socket
import threading
import time
from collections.abc import Iterator

import pytest

from unstack.errors import InvalidArgument
from unstack.sim import dataset
from unstack.sim.dataset import (
    SchedulerUnavailable,
    check_jobs_or_scheduler,
    check_scheduler_address,
    connect_scheduler,
)


@pytest.mark.parametrize("address", ["tcp://10.0.0.5:8786", "10.0.0.5:8786", "tcp://scheduler.lan:1"])
def test_a_tcp_address_is_taken_as_given(address: str) -> None:
    assert check_scheduler_address(address) == address


@pytest.mark.parametrize(
    ("address", "message"),
    [
        ("tls://10.0.0.5:8786", r"^scheduler: tls:// needs dask's security settings, which unstack does not take"),
        ("ucx://10.0.0.5:8786", r"^scheduler: ucx:// needs dask's UCX settings"),
        ("tcp://127.0.0.1:99999", r"^scheduler: expected a port from 1 to 65535, got 99999"),
        ("tcp://127.0.0.1:0", r"^scheduler: expected a port from 1 to 65535, got 0"),
        ("", r"^scheduler: expected an address like tcp://HOST:PORT, got ''"),
        ("http://127.0.0.1:8786", r"^scheduler: expected an address like tcp://HOST:PORT, got 'http://"),
        ("tcp://:8786", r"^scheduler: expected an address like tcp://HOST:PORT"),
    ],
)
def test_an_address_unstack_cannot_use_is_refused_before_any_connection(address: str, message: str) -> None:
    with pytest.raises(InvalidArgument, match=message):
        connect_scheduler(address)


def test_local_processes_beside_a_scheduler_are_refused() -> None:
    check_jobs_or_scheduler(4, None)
    with pytest.raises(InvalidArgument, match=r"^jobs: 3 local processes and a scheduler exclude each other"):
        check_jobs_or_scheduler(3, "tcp://127.0.0.1:8786")


@pytest.fixture
def silent_server() -> Iterator[str]:
    """A TCP server that accepts connections and never answers (a web server waiting for a request)."""
    listener = socket.create_server(("127.0.0.1", 0))
    accepted: list[socket.socket] = []

    def accept() -> None:
        while True:
            try:
                connection, _ = listener.accept()
            except OSError:
                return
            accepted.append(connection)

    threading.Thread(target=accept, daemon=True).start()
    yield f"tcp://127.0.0.1:{listener.getsockname()[1]}"
    listener.close()
    for connection in accepted:
        connection.close()


def test_a_server_that_is_no_dask_scheduler_is_one_line_after_the_timeout(
    silent_server: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(dataset, "SCHEDULER_TIMEOUT", 0.5)
    start = time.monotonic()
    with pytest.raises(SchedulerUnavailable, match=r"answers but not as a dask scheduler \(no handshake within 1 s\)"):
        connect_scheduler(silent_server)
    assert time.monotonic() - start < 10
