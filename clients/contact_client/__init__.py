"""contact_client: the command-line and Python client of contactd (docs/server.md, api/openapi.yaml).

Standard-library HTTP only. Reading and plotting results needs Debian's python3-numpy, python3-h5py and
python3-matplotlib (imported only by the commands and functions that need them).

As a command (clients/contact_client.py, or python3 -m contact_client with clients/ on the path):

    contact_client.py submit api/examples/seed_layers.json --wait -o seed.hdf
    contact_client.py watch ID                # live progress (a tqdm counter on a terminal), resumed with
                                              # Last-Event-ID after a drop; -q: errors only
    contact_client.py status ID | list | cancel ID | delete ID
    contact_client.py download ID -o seed.hdf [--xmf]
    contact_client.py validate my_job.json
    contact_client.py plot seed.hdf -o seed.png [--events events.ndjson] [--xlim LO HI | --xlim full]
                                              [--along auto|arc|x|angle] [--pairs PATTERN,...]
                                              [--max-pairs N] [--overview | --no-overview] [--warp F]
                                              # friction pairs: also the tangential traction, the slip and
                                              # the stick zone per step; many bodies: an overview of all
                                              # bodies and joints; stepped jobs: the load path
    contact_client.py collapse wall.hdf -o wall.png [--body NAME [--point X Y]]
                                              # a collapse analysis: the verdict, the capacity curve and
                                              # the mechanism

    --url (CONTACT_URL, default http://127.0.0.1:8080), --token (CONTACT_TOKEN), --timeout (seconds).
    Exit codes: 0 ok; 1 server, connection or job error (an answer that is not the API's included);
    2 usage or bad input (an invalid job included); 3 the job ended but not SUCCEEDED (submit --wait, watch).

As a module:

    from contact_client import Client, read_result, plot_result
    c = Client("http://127.0.0.1:8080")
    job = c.submit("api/examples/seed_layers.json")
    final = c.wait(job["id"], on_event=print)
    c.download(job["id"], "seed.hdf")
    r = read_result("seed.hdf")                 # numpy arrays
    x, p = r["steps"][-1]["contacts"]["upper.bottom-lower.top"]["x"], ...["pressure"]

Modules: errors (the exceptions), client (HTTP and the API), sse (event streams), results (reading files, all
or in part), plot (the figure; its parts in plot_profiles, plot_pairs, plot_paths, plot_mesh, plot_wall and
plot_select), plot_collapse (a collapse analysis's view), display (what the commands print), cli (the commands).
"""
from .cli import build_parser, main
from .client import DEFAULT_TIMEOUT, DEFAULT_URL, STREAM_READ_TIMEOUT, Client
from .display import Progress, compact_iterations, format_iteration
from .errors import (EXIT_ERROR, EXIT_JOB, EXIT_OK, EXIT_USAGE, ApiError, BadAnswer, BadInput, ClientError,
                     ConnectionFailed, RequestTimeout)
from .plot import load_curve, load_path, plot_result
from .plot_collapse import capacity_curve, plot_collapse
from .results import ResultFile, joint_results, read_events, read_result

__all__ = ["Client", "ClientError", "ConnectionFailed", "RequestTimeout", "ApiError", "BadInput", "BadAnswer",
           "read_result", "read_events", "ResultFile", "joint_results", "plot_result", "load_curve", "load_path",
           "plot_collapse", "capacity_curve",
           "DEFAULT_URL", "DEFAULT_TIMEOUT", "main"]
