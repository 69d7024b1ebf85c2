"""The last stage of grading: what is rendered from the gradebook (`render`): the grades
file (`csv_files`, formula-safe), the feedback files and summary (`feedback`), the class
report (`class_report`), the similarity of the students' code (`similarity`,
`similarity_report`) and the exports for an LMS (`export`)."""
