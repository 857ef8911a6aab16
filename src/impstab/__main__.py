"""``python -m impstab``: the command line (the same as the ``impstab`` command)."""

from .cli import main

if __name__ == "__main__":
    main()
