"""Studies of the model's output: statistics (the one definition of means and most probable values),
report and figures (``tablegen report``, docs/report.md), validation and validation_report (table draws
against the direct model, docs/VALIDATION.md), solver_comparison (a flow solver's wall hits against
:mod:`surrogate` on the same incident states, for any solver adapter)."""
