;;; HMAC-SHA256 against the test vectors of RFC 4231, section 4.
(import (scheme base) (chibi test) (murdoch wire hmac))

(define (repeat byte n) (make-bytevector n byte))
(define (hex->bytevector hex)
  (let ((bv (make-bytevector (quotient (string-length hex) 2))))
    (do ((i 0 (+ i 1))) ((= i (bytevector-length bv)) bv)
      (bytevector-u8-set! bv i
                          (string->number (substring hex (* 2 i) (+ 2 (* 2 i))) 16)))))
(define (text s) (string->utf8 s))

(test-begin "hmac-sha256 (RFC 4231)")
(test "case 1"
    "b0344c61d8db38535ca8afceaf0bf12b881dc200c9833da726e9376c2e32cff7"
  (hmac-sha256 (repeat #x0b 20) (text "Hi There")))
(test "case 2: key shorter than the block"
    "5bdcc146bf60754e6a042426089575c75a003f089d2739839dec58b964ec3843"
  (hmac-sha256 (text "Jefe") (text "what do ya want for nothing?")))
(test "case 3"
    "773ea91e36800e46854db8ebd09181a72959098b3ef8c122d9635514ced565fe"
  (hmac-sha256 (repeat #xaa 20) (repeat #xdd 50)))
(test "case 4"
    "82558a389a443c0ea4cc819899f2083a85f0faa3e578f8077a2e3ff46729665b"
  (hmac-sha256 (hex->bytevector "0102030405060708090a0b0c0d0e0f10111213141516171819")
               (repeat #xcd 50)))
(test "case 5: truncation is the caller's; the first 128 bits match"
    "a3b6167473100ee06e0c796c2955552b"
  (substring (hmac-sha256 (repeat #x0c 20) (text "Test With Truncation")) 0 32))
(test "case 6: key longer than the block"
    "60e431591ee0b67f0d8a26aacbf5b77f8e0bc6213728c5140546040f0ee37f54"
  (hmac-sha256 (repeat #xaa 131)
               (text "Test Using Larger Than Block-Size Key - Hash Key First")))
(test "case 7: long key and long data"
    "9b09ffa71b942fcb27635fbcd5b0e944bfdc63644f0713938a7f51535c3a35e2"
  (hmac-sha256 (repeat #xaa 131)
               (text (string-append
                      "This is a test using a larger than block-size key and a larger"
                      " than block-size data. The key needs to be hashed before being"
                      " used by the HMAC algorithm."))))
;; Beyond RFC 4231: the edges of the key, worked out by the RFC 2104
;; formula over a separate SHA-256.
(test "an empty key and an empty message"
    "b613679a0814d9ec772f95d778c35fc5ff1697c493715653c6c712144292c5ad"
  (hmac-sha256 (bytevector)))
(test "an empty key as a string"
    "b613679a0814d9ec772f95d778c35fc5ff1697c493715653c6c712144292c5ad"
  (hmac-sha256 "" ""))
(test "a key of exactly a block is used as it is"
    "ce3c639dcb9d8baae5d44c3b8b5e233faab4d1860e07489af5c84f213998bd79"
  (hmac-sha256 (repeat #xaa 64) "x"))
(test "a key one byte over a block is hashed first"
    "c2b9a0a013df029c7d812c5ac18388feef0194ee64fcc5f321d149c06137caa3"
  (hmac-sha256 (repeat #xaa 65) "x"))

;; The C keeps the last key's pads for the next call under the same key:
;; every change of key must be seen, whatever its length or object.
(define jefe-mac "5bdcc146bf60754e6a042426089575c75a003f089d2739839dec58b964ec3843")
(define jefe-text "what do ya want for nothing?")
(test "the same key twice" (list jefe-mac jefe-mac)
  (list (hmac-sha256 (text "Jefe") jefe-text) (hmac-sha256 (text "Jefe") jefe-text)))
(test "a key of the same length, one byte other"
    "f8d53118ce0680a281eda49c53a20bf1332f9440d35b08e3545dfb8877dde5a6"
  (begin (hmac-sha256 (text "Jefe") jefe-text)
         (hmac-sha256 (text "Jefd") jefe-text)))
(test "back to the first key" jefe-mac
  (begin (hmac-sha256 (text "Jefd") jefe-text)
         (hmac-sha256 (text "Jefe") jefe-text)))
(test "a prefix of the last key"
    "b613679a0814d9ec772f95d778c35fc5ff1697c493715653c6c712144292c5ad"
  (begin (hmac-sha256 (text "Jefe") "") (hmac-sha256 (bytevector) "")))
(test "a bytevector changed in place is another key"
    "f8d53118ce0680a281eda49c53a20bf1332f9440d35b08e3545dfb8877dde5a6"
  (let ((k (text "Jefe")))
    (hmac-sha256 k jefe-text)
    (bytevector-u8-set! k 3 (char->integer #\d))
    (hmac-sha256 k jefe-text)))
(test "a string key and a bytevector key of the same bytes agree" jefe-mac
  (begin (hmac-sha256 (text "Jefd") jefe-text) (hmac-sha256 "Jefe" jefe-text)))
(test "alternating keys, as two processes' frames would" #t
  (let loop ((i 0))
    (or (= i 100)
        (and (equal? (hmac-sha256 (text "Jefe") jefe-text) jefe-mac)
             (equal? (hmac-sha256 (repeat #x0b 20) (text "Hi There"))
                     "b0344c61d8db38535ca8afceaf0bf12b881dc200c9833da726e9376c2e32cff7")
             (loop (+ i 1))))))
(test "a call that failed on a part leaves nothing behind" jefe-mac
  (begin (guard (e (#t #f)) (hmac-sha256 (text "Jefe") "half a message" 'what))
         (hmac-sha256 (text "Jefe") jefe-text)))
(test-error "a key that is neither bytes nor text"
  (hmac-sha256 'jefe jefe-text))

(test "a string message is its UTF-8 bytes"
    "5bdcc146bf60754e6a042426089575c75a003f089d2739839dec58b964ec3843"
  (hmac-sha256 (text "Jefe") "what do ya want for nothing?"))
(test "a non-ASCII message as a string hashes its UTF-8 bytes"
  (hmac-sha256 (text "Jefe") (text "caf\xe9;"))
  (hmac-sha256 (text "Jefe") "caf\xe9;"))
(test "the parts of a message are hashed one after the other"
    "5bdcc146bf60754e6a042426089575c75a003f089d2739839dec58b964ec3843"
  (hmac-sha256 (text "Jefe") "what do " (text "ya want") " for nothing?"))
(test "a fixnum part stands for its decimal digits"
  (hmac-sha256 (text "Jefe") "nonce:1234567:-5")
  (hmac-sha256 (text "Jefe") "nonce:" 1234567 ":" -5))
(test-error "a part that is neither bytes, text nor a fixnum"
  (hmac-sha256 (text "Jefe") 'what))

;; Signed texts, as frames carry them: the MAC, then the text.
(define key (text "Jefe"))
(define (signed t . parts) (string->utf8 (hmac-sha256-sign key t parts)))
(define (open-all bytes . parts)
  (hmac-sha256-open key bytes (bytevector-length bytes) parts))
(test "a signature is the MAC of the parts and the text, then the text"
  (string-append (hmac-sha256 key "n:" 7 ":" "(hello)") "(hello)")
  (hmac-sha256-sign key "(hello)" '("n:" 7 ":")))
(test "a signed text opens with the same parts" "(hello)"
  (open-all (signed "(hello)" "n:" 7 ":") "n:" 7 ":"))
(test "a non-ASCII text opens as it was" "caf\xe9;"
  (open-all (signed "caf\xe9;" "n:") "n:"))
(test "not with other parts" #f
  (open-all (signed "(hello)" "n:" 7 ":") "n:" 8 ":"))
(test "a frame's (NONCE . COUNT) is the parts NONCE \":\" COUNT \":\""
    (hmac-sha256-sign key "(hello)" '("n" ":" 7 ":"))
  (hmac-sha256-sign key "(hello)" '("n" . 7)))
(test "and opens what they signed" "(hello)"
  (hmac-sha256-open key (signed "(hello)" "n" ":" 7 ":") 71 '("n" . 7)))
(test "not with another count" #f
  (hmac-sha256-open key (signed "(hello)" "n" ":" 7 ":") 71 '("n" . 8)))
(test "not with a byte of the text changed" #f
  (let ((b (signed "(hello)" "n:")))
    (bytevector-u8-set! b 65 (char->integer #\j))
    (open-all b "n:")))
(test "not under another key" #f
  (hmac-sha256-open (text "other") (signed "(hello)") 71 '()))
(test "fewer than 64 bytes do not open" #f
  (hmac-sha256-open key (bytevector 1 2 3) 3 '()))
(test "only the first end bytes are the message" "(hello)"
  (let ((b (signed "(hello)")))
    (hmac-sha256-open key (bytevector-append b (bytevector 0 0))
                      (bytevector-length b) '())))
(test-error "an end past the bytes"
  (hmac-sha256-open key (signed "(hello)") 100 '()))
(test-error "parts that are not a list"
  (hmac-sha256-sign key "(hello)" "n:"))
(test-error "a text that is not a string"
  (hmac-sha256-sign key 'hello '()))
;; A frame is written as the netstring of its signed text, with no string
;; made of it: "LENGTH:" then the signed text, then ",".
(define (written-frame t . parts)
  (let ((out (open-output-string)))
    (hmac-sha256-write! key t parts out)
    (get-output-string out)))
(test "a frame written is the netstring of the signed text"
    (let ((signed (hmac-sha256-sign key "(caf\xe9; 1)" '("n:" 7 ":"))))
      (string-append (number->string (bytevector-length (string->utf8 signed))) ":"
                     signed ","))
  (written-frame "(caf\xe9; 1)" "n:" 7 ":"))
(test-error "a frame is not written to a closed port"
  (let ((out (open-output-string)))
    (close-port out)
    (hmac-sha256-write! key "(hello)" '() out)))
(test-end)
(test-exit)
