"""The scenario format: schema, validation of every field and shape, safe file reading,
one-line messages, the collision probe of starts and goals."""
