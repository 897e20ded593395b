;;;; HMAC-SHA256 (RFC 2104) over Chibi's native SHA-256.
;;
;; Chibi answers SHA-256 as a hex string; HMAC's outer hash needs the inner
;; digest as bytes, so hex goes back to bytes once per frame.

(define sha-256-block-size 64)

(define (hex->bytevector hex)
  (let* ((n (quotient (string-length hex) 2))
         (bv (make-bytevector n)))
    (do ((i 0 (+ i 1))) ((= i n) bv)
      (bytevector-u8-set!
       bv i (string->number (substring hex (* 2 i) (+ 2 (* 2 i))) 16)))))

(define (bytevector-xor-pad key byte)
  (let ((pad (make-bytevector sha-256-block-size byte)))
    (do ((i 0 (+ i 1))) ((= i (bytevector-length key)) pad)
      (bytevector-u8-set! pad i (bitwise-xor byte (bytevector-u8-ref key i))))))

;;> Returns a procedure that computes HMAC-SHA256 under \var{key} (a
;;> bytevector) of its argument, a bytevector, as a lowercase hex string.
;;> The padded keys are computed once, not per message.
(define (make-hmac-sha256 key)
  (let* ((key (if (> (bytevector-length key) sha-256-block-size)
                  (hex->bytevector (sha-256 key))
                  key))
         (inner-pad (bytevector-xor-pad key #x36))
         (outer-pad (bytevector-xor-pad key #x5c)))
    (lambda (message)
      (sha-256
       (bytevector-append
        outer-pad
        (hex->bytevector (sha-256 (bytevector-append inner-pad message))))))))

;;> HMAC-SHA256 of \var{message} under \var{key}, both bytevectors, as a
;;> lowercase hex string.
(define (hmac-sha256 key message)
  ((make-hmac-sha256 key) message))
