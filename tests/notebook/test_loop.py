"""The render loop: requests never wait for a picture, the newest wins, reduced frames are refined."""

from __future__ import annotations

import threading

import pytest

from volumen.notebook import RenderLoop


def _loop(gate: threading.Event | None = None):
    delivered = []

    def draw(state, fraction):
        if gate is not None:
            assert gate.wait(30)
        return f"{state}@{fraction}"

    loop = RenderLoop(draw, lambda frame, req: delivered.append(frame), refine_after=0.01)
    return loop, delivered


def test_requests_return_while_a_frame_is_being_drawn_and_the_newest_wins():
    gate = threading.Event()
    loop, delivered = _loop(gate)
    try:
        loop.request("a")           # the thread starts drawing "a" and blocks on the gate
        for state in "bcd":         # the caller is never blocked: these return at once
            loop.request(state)
        assert delivered == []      # nothing finished yet, yet every request returned
        gate.set()
        assert loop.wait(30)
        assert delivered in (["a@1.0", "d@1.0"], ["d@1.0"])  # b and c were replaced before they started
    finally:
        loop.close()


def test_a_reduced_frame_is_followed_by_the_full_one_when_no_request_comes():
    loop, delivered = _loop()
    try:
        loop.request("drag", 0.5)
        assert loop.wait(30)
        assert delivered == ["drag@0.5", "drag@1.0"]
    finally:
        loop.close()


def test_a_failing_draw_is_reported_by_wait_and_the_loop_goes_on():
    def draw(state, fraction):
        if state == "bad":
            raise ValueError("bad setting")
        return state

    delivered = []
    loop = RenderLoop(draw, lambda frame, req: delivered.append(frame))
    try:
        loop.request("bad")
        with pytest.raises(ValueError, match="bad setting"):
            loop.wait(30)
        loop.request("good")
        assert loop.wait(30) and delivered == ["good"]
    finally:
        loop.close()
