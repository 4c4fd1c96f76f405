"""Every ``robotale`` command's handler, one module per command (group).

A handler takes typed keyword arguments (never an argparse namespace), prints what the user
asked for and returns the exit status; :mod:`robotale.cli` only declares the arguments and
calls it. The parts below (``fame_runtime`` ... ``webapp``) never import this package, and
no command module imports another: what two commands share lives in the part below them that
owns it.
"""
