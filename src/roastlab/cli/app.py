"""``roastlab app``: the roaster's page on this machine (:mod:`roastlab.app.server`)."""

from __future__ import annotations

import argparse
import sys

from ..errors import InputError


def cmd_app(args) -> int:
    try:
        import uvicorn

        from ..app.server import create_app
    except ImportError as exc:
        raise InputError(f"the page needs the app extra: pip install 'roastlab[app]' ({exc.name} missing)") from None
    app = create_app(args.data_dir)
    if args.host not in ("127.0.0.1", "localhost", "::1"):
        print(f"warning: serving on {args.host}: anyone who can reach this machine can use the page", file=sys.stderr)
    config = uvicorn.Config(app, host=args.host, port=args.port, log_level="warning")
    server = uvicorn.Server(config)
    url = f"http://{args.host}:{args.port}/"
    print(f"roastlab app: {url} (data folder {args.data_dir}); Ctrl-C stops it", file=sys.stderr)
    if not args.no_browser:
        import threading
        import webbrowser

        threading.Timer(1.0, lambda: webbrowser.open(url)).start()
    server.run()
    return 0


def add_parsers(sub) -> None:
    """Register this module's command(s) on the ``roastlab`` subparsers ``sub``."""
    p = sub.add_parser(
        "app",
        help="the roaster's page: curves, live what-if and transfer in the browser",
        description="Start a local page over DATA_DIR: open a log and a model file (MODEL.json, from 'roastlab "
        "identify') from the folder (or upload a log), "
        "see measured and predicted BT, the beans, RoR and the settings in Artisan's conventions, change the "
        "charge, batch or settings and see the prediction and the milestone table follow, run a transfer and "
        "download the program and an Artisan background. Binds 127.0.0.1; serves nothing outside DATA_DIR.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="example:\n  roastlab app --data-dir roasts/          (put logs and model files in roasts/)",
    )
    p.add_argument("--data-dir", default=".", metavar="DIR", help="the folder of logs and models (default: here)")
    p.add_argument("--host", default="127.0.0.1", help="address to bind (default %(default)s, this machine only)")
    p.add_argument("--port", type=int, default=8765, help="port (default %(default)s)")
    p.add_argument("--no-browser", action="store_true", help="print the URL, do not open a browser")
    p.set_defaults(func=cmd_app)
