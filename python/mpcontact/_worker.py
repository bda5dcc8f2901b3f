"""The worker processes of ``mpcontact.run``.

``run`` starts each worker as ``python -c CODE worker --run RUN --index K``
(see ``_worker_command`` in ``__init__``); CODE imports this module from the
same installation as the coordinator and calls :func:`main`, which runs the
Rust worker (``worker::run_worker``, what ``mpcontact worker`` runs) in this
process. The coordinator, the protocol and the worker code are those of the
CLI; only the host program differs.
"""

import signal
import sys


def main(argv=None):
    """Parse ``worker --run RUN --index K`` and serve the run until it ends."""
    args = list(sys.argv[1:] if argv is None else argv)
    # Ctrl-C in a terminal reaches the whole process group: a worker dies of
    # it like the CLI's (which installs no handler), instead of Python turning
    # it into a KeyboardInterrupt that Rust code would never see.
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    if len(args) != 5 or args[0] != "worker" or args[1] != "--run" or args[3] != "--index":
        sys.exit(f"usage: worker --run RUN --index K (got {' '.join(args)})")
    from mpcontact import _native

    # The exit status tells the coordinator how the worker ended (as the
    # CLI's `mpcontact worker` does): 3 = left while waiting, holding no case.
    sys.exit(_native.worker(args[2], int(args[4])))


if __name__ == "__main__":
    main()
