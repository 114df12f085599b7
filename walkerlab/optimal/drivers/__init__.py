"""Set-ups of ``walkerlab optimize`` from a scene: transcription, replay, records."""
