"""The fourth stage of grading: the term's rules applied to the points: due dates and late
penalties (`late`, `term_options`), manual changes (`adjustments`), each row's final points
(`final_points`), and the instructor files' mistakes named by file and line (`problems`)."""
