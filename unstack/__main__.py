"""``python -m unstack`` runs the command line."""

from unstack.cli.main import main

if __name__ == "__main__":
    main()
