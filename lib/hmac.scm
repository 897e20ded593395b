;;;; HMAC-SHA256 (RFC 2104): the primitive is lib/hmac.c.
;;
;; Chibi has SHA-256 but no HMAC.  Written in Scheme over Chibi's SHA-256
;; it cost 40 us a frame, nearly all of it building byte strings a byte at
;; a time; the remote layer MACs every frame twice, so it is C.

;;> Returns a procedure that computes HMAC-SHA256 under \var{key} (a
;;> bytevector) of the parts it is given, as hmac-sha256 does.
(define (make-hmac-sha256 key)
  (lambda parts (apply hmac-sha256 key parts)))
