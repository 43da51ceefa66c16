"""Result objects, response statistics and the result document."""
