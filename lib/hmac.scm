;;;; HMAC-SHA256 (RFC 2104) over Chibi's native SHA-256.
;;
;; Chibi hashes strings and bytevectors in C, but building a bytevector
;; byte by byte runs in Scheme at about a microsecond a byte.  So when the
;; padded keys are ASCII (as the lab's hex keys always are) and the message
;; is a string, the inner hash is taken over a string-append, which costs
;; nothing; only the outer hash needs the inner digest as bytes.  Either way
;; the result is HMAC over the message's UTF-8 bytes.

(define sha-256-block-size 64)

(define (hex-digit-value b)              ; an ASCII byte: 0-9 or a-f
  (if (< b 58) (- b 48) (- b 87)))

;; Writes the bytes that \var{hex} spells into \var{bv} from \var{at}.
;; It works on the string's bytes: string-ref walks a UTF-8 string.
(define (hex-into! bv at hex)
  (let ((digits (string->utf8 hex)))
    (do ((i 0 (+ i 1))) ((= i (quotient (bytevector-length digits) 2)) bv)
      (bytevector-u8-set!
       bv (+ at i)
       (+ (* 16 (hex-digit-value (bytevector-u8-ref digits (* 2 i))))
          (hex-digit-value (bytevector-u8-ref digits (+ 1 (* 2 i)))))))))

;;> The bytes that a lowercase hex string spells.
(define (hex->bytevector hex)
  (hex-into! (make-bytevector (quotient (string-length hex) 2)) 0 hex))

(define (bytevector-xor-pad key byte)
  (let ((pad (make-bytevector sha-256-block-size byte)))
    (do ((i 0 (+ i 1))) ((= i (bytevector-length key)) pad)
      (bytevector-u8-set! pad i (bitwise-xor byte (bytevector-u8-ref key i))))))

(define (ascii? bv)
  (let loop ((i 0))
    (or (= i (bytevector-length bv))
        (and (< (bytevector-u8-ref bv i) 128) (loop (+ i 1))))))

(define (concatenate a b)
  (let ((out (make-bytevector (+ (bytevector-length a) (bytevector-length b)))))
    (bytevector-copy! out 0 a)
    (bytevector-copy! out (bytevector-length a) b)
    out))

;;> Returns a procedure that computes HMAC-SHA256 under \var{key} (a
;;> bytevector) of its argument, a bytevector or a string, as a lowercase
;;> hex string.  The padded keys are computed once, not per message.
(define (make-hmac-sha256 key)
  (let* ((key (if (> (bytevector-length key) sha-256-block-size)
                  (hex->bytevector (sha-256 key))
                  key))
         (inner-pad (bytevector-xor-pad key #x36))
         (outer-pad (bytevector-xor-pad key #x5c))
         (inner-pad-string (and (ascii? inner-pad) (utf8->string inner-pad)))
         (outer-template (concatenate outer-pad (make-bytevector 32 0))))
    ;; bytevector-copy of a whole bytevector is done in C.
    (define (outer inner-hex)
      (sha-256 (hex-into! (bytevector-copy outer-template) sha-256-block-size
                          inner-hex)))
    (lambda (message)
      (if (and (string? message) inner-pad-string)
          (outer (sha-256 (string-append inner-pad-string message)))
          (outer (sha-256 (concatenate inner-pad
                                       (if (string? message)
                                           (string->utf8 message)
                                           message))))))))

;;> HMAC-SHA256 of \var{message} (a bytevector or string) under \var{key},
;;> a bytevector, as a lowercase hex string.
(define (hmac-sha256 key message)
  ((make-hmac-sha256 key) message))
