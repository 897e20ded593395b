;;> Netstrings, the frames every Murdoch message travels in, the
;;> nesting scan a message passes before it is read, and the reading in C
;;> of a plain message.

(define-library (murdoch wire netstring)
  (export read-netstring write-netstring buffered-byte-count
          reset-output-string! nests-within? plain-message fields-pass? fixnum->decimal
          netstring-error? netstring-error-message)
  (import (scheme base) (only (chibi) string-size)
          (murdoch wire remote-error))
  (include-shared "netstring")
  (include "netstring.scm"))
