"""The second stage of grading: each submission's checks run by a judge process, its code in
a sandbox (`grading`, `judges`, `sandbox`, `sandbox_child`, `wire`, `pytest_sandbox`,
`processes`), on a Dask cluster (`cluster_grading`) or in Gradescope's autograder
(`gradescope`)."""
