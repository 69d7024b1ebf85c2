"""The third stage of grading: the points, kept in the gradebook database (`gradebook_db`)
with the columns of the grades file (`gradebook`)."""
