"""Statistics across runs: ``holecell spc`` (individuals / moving-range charts, Cp/Cpk per
characteristic) from the runs' ``report.qif`` files. See docs/spc.md."""
