"""The bundle's executable (installer/feelflow.spec): `feelflow ARGS` runs the `feelflow`
command; `feelflow -m feelflow.MODULE ARGS` runs that module as `python -m` would.

Inside the bundle `sys.executable` is this program, so the children FeelFlow starts as
`[sys.executable, "-m", module, ...]` (the haptic loop, the serial simulators) work frozen and
from a checkout alike.
"""
import runpy
import sys


def main() -> int:
    argv = sys.argv
    if len(argv) >= 2 and argv[1] == "-m":
        module = argv[2] if len(argv) >= 3 else ""
        if not (module == "feelflow" or module.startswith("feelflow.")):
            print(f"feelflow: -m runs FeelFlow's own modules only (feelflow.*), not {module or 'nothing'!r}",
                  file=sys.stderr)
            return 2
        sys.argv = [argv[0]] + argv[3:]
        runpy.run_module(module, run_name="__main__", alter_sys=True)
        return 0
    from feelflow.app.cli.main import main as feelflow_main

    return feelflow_main()


if __name__ == "__main__":
    sys.exit(main())
