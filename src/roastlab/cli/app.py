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
    sock = _bound_socket(args.host, args.port)  # before the URL is printed: a port in use is said, not served
    if args.host not in ("127.0.0.1", "localhost", "::1"):
        print(f"warning: serving on {args.host}: anyone who can reach this machine can use the page", file=sys.stderr)
    port = sock.getsockname()[1]  # --port 0: the one the system gave
    server = uvicorn.Server(uvicorn.Config(app, host=args.host, port=port, log_level="warning"))
    host = f"[{args.host}]" if ":" in args.host else args.host
    url = f"http://{host}:{port}/"
    print(f"roastlab app: {url} (data folder {args.data_dir}); Ctrl-C stops it", file=sys.stderr)
    if not args.no_browser:
        import threading
        import webbrowser

        threading.Timer(1.0, lambda: webbrowser.open(url)).start()
    server.run(sockets=[sock])
    return 0


def _bound_socket(host: str, port: int):
    """A listening-ready socket bound to ``host``:``port``, or one line saying why not (InputError:
    exit code 2): another program (another ``roastlab app``) on the port, or an address this machine
    does not have."""
    import errno
    import socket

    try:
        found = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)
    except (socket.gaierror, UnicodeError) as exc:
        raise InputError(f"--host {host}: not an address of this machine ({exc})", "command line") from None
    # a name with both (localhost): its IPv4 address, as uvicorn takes it
    family, kind, proto, _, address = next((a for a in found if a[0] == socket.AF_INET), found[0])
    sock = socket.socket(family, kind, proto)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # as uvicorn: a restart need not wait out TIME_WAIT
    try:
        sock.bind(address)
    except OSError as exc:
        sock.close()
        if exc.errno == errno.EADDRINUSE:
            why = f"port {port} on {host} is in use (another roastlab app?): choose another with --port, or --port 0 for any free one"
        else:
            why = f"cannot listen on {host}:{port} ({exc.strerror or exc})"
        raise InputError(why, "command line") from None
    return sock


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
    p.add_argument("--port", type=int, default=8765, help="port (default %(default)s; 0: any free one, printed)")
    p.add_argument("--no-browser", action="store_true", help="print the URL, do not open a browser")
    p.set_defaults(func=cmd_app)
