"""The tools of the ropedyn repository: the studies that write docs/ and the maintenance
checks. Not installed (`pip install python/` installs only the user's package `ropedyn`):
the scripts/ commands put tools/ on PYTHONPATH and run a module here with `python -m`, and
the test suite finds it through pytest.ini (`pythonpath = tools`). Every command module has
`main(argv=None)`.

- `ropedyn_tools.repo`: the repository's paths, the executable (Release build), `--set`
  arguments;
- `ropedyn_tools.compare`: a run against a reference, quantity by quantity (the regression
  tests, scripts/update_references);
- `ropedyn_tools.studies.*`: the studies behind docs/ (scripts/work_precision,
  scripts/bench_*, ...; see studies/__init__.py);
- maintenance: `architecture` (scripts/architecture: the layer rule and its page),
  `docs_status` (scripts/docs_status: generated sections older than their code),
  `mutation_check` (scripts/mutation_check: does the suite catch deliberate bugs),
  `update_references` (scripts/update_references: the regression references).

The tools use the package `ropedyn` (reading runs, plots) from the project venv.
"""
