"""The CLI's entry (stochcable.cli): warnings on stderr, each message once."""

from __future__ import annotations

import warnings

from stochcable.cli import main, warning_printer
from stochcable.errors import ResolutionWarning


def test_the_warning_printer_writes_each_message_once(capsys):
    show = warning_printer()
    for text in ("a", "b", "a", "a", "b", "c"):
        show(ResolutionWarning(text), ResolutionWarning, "f.py", 1)
    assert capsys.readouterr().err.splitlines() == [
        "stochcable: warning: a",
        "stochcable: warning: b",
        "stochcable: warning: c",
    ]


def test_a_command_prints_a_repeated_warning_once(capsys, monkeypatch):
    # one warning issued three times from different places during a command
    def run(args):
        for _ in range(3):
            warnings.warn("the same thing", ResolutionWarning, stacklevel=1)
        warnings.warn("another thing", ResolutionWarning, stacklevel=1)
        return 0

    import stochcable.cli.spectrum as spectrum

    monkeypatch.setattr(spectrum, "run", run)
    monkeypatch.setattr(warnings, "showwarning", warnings.showwarning)
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        assert main(["spectrum", "pm", "--hs", "2", "--tp", "8"]) == 0
    err = capsys.readouterr().err.splitlines()
    assert err == ["stochcable: warning: the same thing", "stochcable: warning: another thing"]
