import subprocess
import sys

from robotale import __version__
from robotale.cli import main


def test_version(capsys):
    try:
        main(["--version"])
    except SystemExit as done:
        assert done.code == 0
    assert capsys.readouterr().out.strip() == f"robotale {__version__}"


def test_module_entry_point_runs():
    result = subprocess.run(
        [sys.executable, "-m", "robotale", "--version"], capture_output=True, text=True
    )
    assert result.returncode == 0
    assert result.stdout.strip() == f"robotale {__version__}"


def test_pm4py_banner_stays_out_of_robotale_output():
    # pm4py shows its banner when the importing script is __main__: exactly our situation
    # when a user's script (or the CLI) imports robotale first and pm4py after it.
    script = "import robotale, pm4py"
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert result.returncode == 0
    assert "Welcome to" not in result.stderr + result.stdout
    without = subprocess.run([sys.executable, "-c", "import pm4py"], capture_output=True, text=True)
    assert "Welcome to" in without.stderr, "the check above would not notice a banner"
