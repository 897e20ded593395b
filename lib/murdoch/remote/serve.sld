;;> The callee's side of the wire: accepting connections, reading and
;;> running calls, and the janitor.

(define-library (murdoch remote serve)
  (export start-serving! hand-over-connection! release-call!
          new-serving! read-as-reader reader? read-calls serve-call
          make-served-call served-call-caller served-call-id reply!
          serving-read-on serving-read-on-set! screen-calls!)
  (import (scheme base) (srfi 1) (srfi 18)
          (only (chibi filesystem) open-input-file-descriptor open-output-file-descriptor)
          (only (chibi) port-fileno)
          (chibi net) (murdoch sys) (murdoch code) (murdoch wire)
          (murdoch lab) (murdoch remote aspace) (murdoch remote worker)
          (murdoch remote call)
          (only (murdoch remote connection) watch-served! unwatch-served!))
  (include "serve.scm" "served-call.scm"))
