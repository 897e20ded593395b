;;> Scripted REPL sessions (docs/transcripts.md): reading a transcript,
;;> and comparing what a REPL printed with what it expects.
(define-library (murdoch transcript)
  (export read-transcript read-doc-transcript transcript-lab transcript-as transcript-steps
          transcript-shell transcript-script
          prompt-count transcript-mismatches line-matches?)
  (import (scheme base) (scheme char) (scheme file) (srfi 1)
          (only (murdoch testing) read-lines))
  (include "transcript.scm"))
