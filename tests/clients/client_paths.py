"""Imported first by every test in this folder: puts the shared check module (tests/checks.py), the server
harness (tests/server/harness.py) and the client package (clients/) on the import path, and names the paths
the tests use. CONTACT_SOURCE_DIR (set by CTest) overrides the source tree found from this file."""
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
SRC = os.environ.get("CONTACT_SOURCE_DIR", os.path.join(HERE, "..", ".."))
for folder in (os.path.join(SRC, "clients"), os.path.join(SRC, "tests", "server"), os.path.join(SRC, "tests")):
    if folder not in sys.path:
        sys.path.insert(0, folder)
CLIENT = os.path.join(SRC, "clients", "contact_client.py")
EXAMPLES = os.path.join(SRC, "api", "examples")
