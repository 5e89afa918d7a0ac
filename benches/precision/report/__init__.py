"""docs/BENCHMARKS.md and docs/work_precision.png from the CSVs of `make bench`
(`document.write`): the names of the suites (`names`), the curves read from the CSVs
(`curves`), the figure (`plot`), the reasons behind the verdicts (`analysis`)."""
