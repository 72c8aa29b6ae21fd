"""python3 -m contact_client ... (the same as clients/contact_client.py)."""
import sys

from .cli import main

sys.exit(main())
