"""Running a command line in the test process and checking its one-line user errors."""


def run_cli(main, argv, capsys):
    """(exit status, stderr lines, stdout) of ``main(argv)``; argparse's own errors exit through SystemExit."""
    try:
        code = main(argv)
    except SystemExit as exc:
        code = exc.code
    captured = capsys.readouterr()
    return code, captured.err.splitlines(), captured.out


def user_error(main, argv, capsys, *words):
    """Assert ``main(argv)`` ends in exactly one line on stderr and exit 2, holding every word; (line, stdout)."""
    code, err, out = run_cli(main, argv, capsys)
    assert code == 2 and len(err) == 1 and ": error: " in err[0], err
    for word in words:
        assert word in err[0], err[0]
    return err[0], out
