;;; The strict netstring reader: good frames, and each kind of bad one.
(import (scheme base) (chibi test) (chibi io) (murdoch wire netstring))

(define (bytes s) (string->utf8 s))
(define (read-all s max)
  (let ((in (open-input-bytevector (bytes s))))
    (let loop ((acc '()))
      (let ((x (read-netstring in max)))
        (if (eof-object? x) (reverse acc) (loop (cons (utf8->string x) acc)))))))
(define (fault s max)
  (guard (e ((netstring-error? e) (netstring-error-message e)))
    (read-all s max)
    'no-fault))
(define (framed s)
  (let ((out (open-output-bytevector)))
    (write-netstring (bytes s) out)
    (utf8->string (get-output-bytevector out))))

(test-begin "netstring")
(test "one frame" '("hello") (read-all "5:hello," 100))
(test "frames back to back" '("a" "" "bc") (read-all "1:a,0:,2:bc," 100))
(test "empty input is no frame" '() (read-all "" 100))
(test "exactly the maximum" '("abcd") (read-all "4:abcd," 4))
(test "writer" "3:abc," (framed "abc"))
(test "a string is framed by its UTF-8 bytes" "5:caf\xe9;,"
  (let ((out (open-output-bytevector)))
    (write-netstring "caf\xe9;" out)
    (utf8->string (get-output-bytevector out))))
(test "round trip of every byte value" 256
  (let* ((bv (let ((b (make-bytevector 256)))
               (do ((i 0 (+ i 1))) ((= i 256) b) (bytevector-u8-set! b i i))))
         (out (open-output-bytevector)))
    (write-netstring bv out)
    (bytevector-length
     (read-netstring (open-input-bytevector (get-output-bytevector out)) 1000))))
(test "garbage" "non-digit byte 71 in length" (fault "GET / HTTP/1.0" 100))
(test "over-long length" "length 101 over 100 bytes" (fault "101:" 100))
(test "too many digits" "length over 100 bytes" (fault "1000000000:a," 100))
(test "leading zero" "leading zero in length" (fault "01:a," 100))
(test "empty length" "empty length" (fault ":a," 100))
(test "truncated length" "truncated length" (fault "12" 100))
(test "truncated payload" "truncated payload" (fault "5:abc" 100))
(test "missing comma" "missing comma after payload" (fault "3:abc;" 100))
(test "missing comma at end" "missing comma after payload" (fault "3:abc" 100))
(test "minus sign" "non-digit byte 45 in length" (fault "-1:" 100))
;; read-netstring takes a frame that its port's buffer holds whole in one
;; C call, and reads anything else byte by byte.  A port that hands over a
;; byte at a time never holds a whole frame, so it is read byte by byte;
;; the two must agree on every input, frames and faults alike.
(define (trickle bytes)
  (let ((i 0))
    (make-custom-binary-input-port
     (lambda (buf start end)            ; answers the new end of buf
       (if (>= i (bytevector-length bytes))
           start
           (begin (bytevector-u8-set! buf start (bytevector-u8-ref bytes i))
                  (set! i (+ i 1))
                  (+ start 1)))))))

;; The payloads read before the end or the first fault, and the fault.
(define (outcome in max)
  (let loop ((acc '()))
    (let ((x (guard (e ((netstring-error? e) (netstring-error-message e)))
               (read-netstring in max))))
      (cond ((bytevector? x) (loop (cons x acc)))
            ((eof-object? x) (list (reverse acc) 'end))
            (else (list (reverse acc) x))))))

;; Inputs made mostly of the pieces netstrings are made of, from a fixed
;; seed: the same inputs every run.
(define seed 12345)
(define (random-below n)
  (set! seed (modulo (+ (* seed 1103515245) 12345) 2147483648))
  (modulo (quotient seed 65536) n))
(define pieces
  '#("0" "1" "2" "3" "9" "10" "12" ":" "," "a" "bc" "3:abc," "0:," "01:" "-"))
(define (random-input)
  (let loop ((k (random-below 8)) (acc ""))
    (if (zero? k)
        (string->utf8 acc)
        (loop (- k 1)
              (string-append acc (vector-ref pieces
                                             (random-below (vector-length pieces))))))))

(test "the whole-frame and the byte-wise reader agree on 3000 inputs" '()
  (let loop ((i 0) (disagreements '()))
    (if (= i 3000)
        disagreements
        (let ((input (random-input)))
          (loop (+ i 1)
                (if (equal? (outcome (open-input-bytevector input) 10)
                            (outcome (trickle input) 10))
                    disagreements
                    (cons (utf8->string input) disagreements)))))))

(test-end)
(test-exit)
