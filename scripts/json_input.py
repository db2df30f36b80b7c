"""The command line the plotting scripts share: --json <input> and one output option."""
import argparse
import json
import pathlib
import sys


def parse_and_read(prog: str, description: str, json_default: str, out_option: str, out_default: str,
                   keys: tuple[str, ...]) -> tuple[argparse.Namespace, list]:
    """The parsed arguments and the input's values under `keys`; exits with 1, naming the file, when it
    cannot be read or lacks one of them."""
    ap = argparse.ArgumentParser(prog=prog, description=description)
    ap.add_argument("--json", default=json_default)
    ap.add_argument(out_option, default=out_default)
    args = ap.parse_args()
    try:
        data = json.loads(pathlib.Path(args.json).read_text())
        return args, [data[k] for k in keys]
    except (OSError, ValueError, KeyError) as e:
        print(f"{prog}: cannot read {args.json}: {e}", file=sys.stderr)
        sys.exit(1)
