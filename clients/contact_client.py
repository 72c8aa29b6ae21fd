#!/usr/bin/python3
"""contactd's client as a command: clients/contact_client.py COMMAND ... (`--help` lists the commands).

The code is the package next to this file, clients/contact_client/ (which `import contact_client` finds first
when clients/ is on the path: a package wins over a module of the same name). See its docstring.
"""
import os
import sys

if __name__ == "__main__":
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from contact_client.cli import main  # the package, not this file

    sys.exit(main())
