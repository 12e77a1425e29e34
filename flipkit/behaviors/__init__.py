"""Behaviour layer: task-space targets on the grill and the subbehaviour segments (the paper's
eqs. 22–29) built from transcription blocks."""
