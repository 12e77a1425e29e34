"""Transcription layer: the collocation variable layout, initial guesses, the fixed-sparsity
constraint blocks and the NLP that stacks them. Imports the model layer and below."""
