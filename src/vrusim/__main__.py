"""`python -m vrusim`: the same command line as the `vrusim` console script."""

from vrusim.cli.app import main

if __name__ == "__main__":
    main(prog_name="python -m vrusim")
