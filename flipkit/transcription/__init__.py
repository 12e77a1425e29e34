"""Transcription layer: the collocation variable layout, initial guesses, the fixed-sparsity
constraint blocks and the NLP that stacks them, and the NLP restated as one stage-wise CasADi
SX graph. Imports the model layer and below."""
