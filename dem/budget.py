"""Memory budgets: a request is refused up front, in one line with the estimate, when it
needs more than a share of this machine's memory (reads, expansions, stacks)."""

from __future__ import annotations

from craters._shared import human_bytes, physical_memory_bytes

__all__ = ["check_memory_need"]


def check_memory_need(need: float, what: str, change: str = "", *, share: float = 0.8) -> None:
    """A one-line ValueError "WHAT needs about N of memory; this machine has M: CHANGE"
    when ``need`` bytes are more than ``share`` of this machine's memory."""
    have = physical_memory_bytes()
    if need > share * have:
        tail = f": {change}" if change else ""
        raise ValueError(f"{what} needs about {human_bytes(need)} of memory; this machine has "
                         f"{human_bytes(have)}{tail}")
